"""Tail merging (cross-jumping): a block that jumps to T and ends with the instructions
the block falling through to T ends with jumps to those instructions instead, so that
they are written once.

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

from . import flow, ir


def merge_tails(program: ir.Program) -> ir.Program:
    if flow.takes_events(program):
        return program
    while (merge := _longest_shared_tail(program)) is not None:
        jumping, falling, length = merge
        _share(program, jumping, falling, length)
    return program


def _longest_shared_tail(program: ir.Program) -> tuple[ir.Block, ir.Block, int] | None:
    """The jumping block, the falling block and the length of the longest tail they
    share (the first such pair in layout order), or None when no pair shares one."""
    following = program.following()
    falling_into = {block.terminator.target: block for block in program
                    if isinstance(block.terminator, ir.Jump)
                    and following[block.id] == block.terminator.target}
    best: tuple[ir.Block, ir.Block, int] | None = None
    for block in program:
        terminator = block.terminator
        if not isinstance(terminator, ir.Jump) or following[block.id] == terminator.target:
            continue
        falling = falling_into.get(terminator.target)
        if falling is None:
            continue
        length = _shared_length(block.instructions, falling.instructions)
        if length and (best is None or length > best[2]):
            best = (block, falling, length)
    return best


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


def _share(program: ir.Program, jumping: ir.Block, falling: ir.Block, length: int) -> None:
    """The falling block's last `length` instructions split off into a block after it,
    to which the jumping block, without its own copy, jumps."""
    tail_id = _new_id(program)
    tail = falling.instructions[-length:]
    shared = ir.Block(tail_id, tail, falling.terminator)
    falling.instructions = falling.instructions[:-length]
    falling.terminator = ir.Jump(tail_id, tail[0].line)  # the fall-through: not written
    jumping.instructions = jumping.instructions[:-length]
    jumping.terminator = ir.Jump(tail_id, jumping.terminator.line)
    blocks: dict[ir.BlockId, ir.Block] = {}
    for block_id, block in program.blocks.items():
        blocks[block_id] = block
        if block is falling:
            blocks[tail_id] = shared
    program.blocks = blocks


def _new_id(program: ir.Program) -> ir.BlockId:
    """A block id no block has: `Bn`, n past every one in use."""
    numbers = [int(block_id[1:]) for block_id in program.blocks
               if block_id.startswith("B") and block_id[1:].isdigit()]
    return f"B{max(numbers, default=-1) + 1}"
