"""Tail merging (cross-jumping): a block that jumps to T and ends with the instructions
the block falling through to T ends with jumps to those instructions instead, so that
they are written once: split off as a block of their own, laid out where they were,
unless they are the whole falling block, to which the jump then goes.

Assumes: the IR is valid, in the layout order the code generator keeps (a block falls
through to the next one, where its jump to that block is left out); it runs once, after
the passes that rewrite instructions (they would see a tail split off as a block of its
own).
Keeps: every call and jump, each on its line; the values every variable has at every
call and at the end; the budget invariant: the jumping block's path runs as many
instructions as before (its jump goes to the shared tail instead of after it, and the
tail falls through to T), the other's the same ones.

- The shared tail holds no call: a call that faults names its own line, and the two
  blocks' calls have lines of their own. Other instructions cannot fault, so the
  tail's instructions need only be alike but for their lines (the falling block's stay).
- The tail reads neither the accumulator nor R before it sets them (a block starts
  with both unset: ir.validate).
- Only in programs that take no lost-line events (flow.takes_events): an event taken at
  the jump, now before the tail, would see the variables before its stores.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import count

from . import flow, ir


def merge_tails(program: ir.Program) -> ir.Program:
    """One sweep, target by target (the merges for one target change no block of
    another's: a tail is laid out just before its own target); for each, the longest
    shared tail first, so that each shorter one is a tail of it in turn."""
    following = program.following()
    falling_into = {block.terminator.target: block for block in program
                    if isinstance(block.terminator, ir.Jump)
                    and following[block.id] == block.terminator.target}
    jumping_to: dict[ir.BlockId, list[ir.Block]] = {}
    for block in program:
        terminator = block.terminator
        if isinstance(terminator, ir.Jump) and terminator.target in falling_into \
                and following[block.id] != terminator.target:
            jumping_to.setdefault(terminator.target, []).append(block)
    plans = {target: sorted(((_shared_length(block.instructions,
                                             falling_into[target].instructions), block)
                             for block in jumping), key=lambda pair: -pair[0])
             for target, jumping in jumping_to.items()}
    # The scan for events last, where a tail is shared: it costs the most.
    if not any(plan[0][0] for plan in plans.values()) or flow.takes_events(program):
        return program
    numbers = count(_first_free_number(program))
    split_off: dict[ir.BlockId, list[ir.Block]] = {}  # laid out after the block, in order
    for target, shared in plans.items():
        first = falling = falling_into[target]
        for length, block in shared:
            if not length:
                break
            if length < len(falling.instructions):
                falling = _split(falling, length, f"B{next(numbers)}")
                split_off.setdefault(first.id, []).append(falling)
            block.instructions = block.instructions[:-length]
            block.terminator = ir.Jump(falling.id, block.terminator.line)
    if split_off:
        program.blocks = {each.id: each for block in program
                          for each in (block, *split_off.get(block.id, ()))}
    return program


def _shared_length(first: list[ir.Instruction], second: list[ir.Instruction]) -> int:
    """How many instructions at the end of both are alike (lines aside) and can make a
    block of their own: no call among them, the accumulator and R not read unset."""
    alike = 0
    for one, other in zip(reversed(first), reversed(second), strict=False):
        if isinstance(one, ir.Call) or replace(one, line=0) != replace(other, line=0):
            break
        alike += 1
    return next((length for length in range(alike, 0, -1)
                 if _starts_a_block(second[len(second) - length:])), 0)


def _starts_a_block(instructions: list[ir.Instruction]) -> bool:
    """Whether the instructions read the accumulator only after setting it, and R never
    (they hold no call, which alone sets it)."""
    loaded = False
    for instruction in instructions:
        if any(isinstance(operand, ir.Result) for operand in ir.operands(instruction)):
            return False
        if isinstance(instruction, ir.Operate | ir.Store) and not loaded:
            return False
        loaded = loaded or isinstance(instruction, ir.Load | ir.Compute)
    return True


def _split(block: ir.Block, length: int, tail_id: ir.BlockId) -> ir.Block:
    """The block's last `length` instructions as a block of their own with its
    terminator, to which the block, without them, falls through."""
    tail = ir.Block(tail_id, block.instructions[-length:], block.terminator)
    block.instructions = block.instructions[:-length]
    block.terminator = ir.Jump(tail_id, tail.instructions[0].line)  # not written
    return tail


def _first_free_number(program: ir.Program) -> int:
    """The first n past every `Bn` block id in use."""
    return max((int(block_id[1:]) for block_id in program.blocks
                if block_id.startswith("B") and block_id[1:].isdigit()), default=-1) + 1
