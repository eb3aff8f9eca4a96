"""Dead store removal: a store (or a step) whose value no one can see.

Assumes: the IR is valid (the accumulator is dead where a block starts).
Keeps: every call and terminator; the value of every variable wherever it can be seen
(spec/optimization.md, section 2): at the end, at every call (which can fault, and
after which an event can be taken) and, in a program that can take lost-line events,
at every jump (where an event can be taken).

A backward data flow over the variables: a variable is live where some path reads it
before writing it, or reaches one of those points first. A store or a step of a
variable that is not live goes, and with a store the load and operations that computed
its value, when nothing else uses the accumulator (they have no other effect; a call
among them stays).
"""

from __future__ import annotations

from array import array

from rl1.vm.language import VARIABLES

from . import flow, ir

ALL = frozenset(VARIABLES)


def remove_dead_stores(program: ir.Program) -> ir.Program:
    for block_id, kept in _solve(program, flow.takes_events(program)).items():
        program.blocks[block_id].instructions = kept
    return program


def _live_out(block: ir.Block, live_in: list[frozenset[str] | None],
              position: dict[ir.BlockId, int], events: bool) -> frozenset[str]:
    terminator = block.terminator
    if isinstance(terminator, ir.End) or events:
        return ALL  # the final variables; or a handler (or a fault) after a jump
    live = frozenset().union(*(live_in[position[target]] or frozenset()
                               for target in terminator.targets))
    return live | {terminator.var.name} if isinstance(terminator, ir.Branch) else live


def _solve(program: ir.Program, events: bool) -> dict[ir.BlockId, list[ir.Instruction]]:
    """The instructions without their dead ones of each block that has some, from what
    is live where each block starts: a worklist, each block swept again when what is
    live after it grows (its last sweep is the one with the final liveness).

    Blocks go by their place in the layout, and what the flow holds of each is in lists
    and arrays by place (a block a line of `?A=#01` held 300 bytes of dictionaries and
    lists of the flow a block, 42 bytes a source byte)."""
    places = flow.Places(program)
    blocks, position = places.blocks, places.place
    live_in: list[frozenset[str] | None] = [None] * len(blocks)
    # One object for equal sets: most blocks of a long program see every variable live
    # (a set of 53 names is 2 KB; 8 MiB of `?A=#01` lines held 370 bytes a source byte).
    shared: dict[frozenset[str], frozenset[str]] = {}
    kept: dict[int, list[ir.Instruction]] = {}  # of the blocks that lose instructions
    work = array("I", range(len(blocks)))  # popped from the end: the last block first
    queued = bytearray(b"\x01") * len(blocks)
    while work:
        place = work.pop()
        queued[place] = 0
        block = blocks[place]
        swept, live = _sweep(block, _live_out(block, live_in, position, events))
        if len(swept) < len(block.instructions):
            kept[place] = swept
        else:
            kept.pop(place, None)
        if live_in[place] != live and not events:  # with events, all is live after each
            live_in[place] = shared.setdefault(live, live)
            for pred in places.predecessors(place):
                if not queued[pred]:
                    queued[pred] = 1
                    work.append(pred)
    return {blocks[place].id: instructions for place, instructions in kept.items()}


def _sweep(block: ir.Block, live_out: frozenset[str]
           ) -> tuple[list[ir.Instruction], frozenset[str]]:
    """The block's instructions without its dead ones, and what is live where it
    starts."""
    live = set(live_out)
    terminator = block.terminator
    if isinstance(terminator, ir.StoreBranch):
        live.discard(terminator.var.name)  # stored here, from the accumulator
    elif isinstance(terminator, ir.DecrementBranch):
        live.add(terminator.var.name)
    # Whether an instruction after this point reads the accumulator.
    acc_used = isinstance(terminator, ir.StoreBranch)
    kept: list[ir.Instruction] = []
    # isinstance, not match: class patterns made this sweep 20% slower (CPython 3.11).
    for instruction in reversed(block.instructions):
        if isinstance(instruction, ir.Call):
            live = set(ALL)  # a fault here shows every variable
        elif isinstance(instruction, ir.Move):
            if instruction.target.name not in live:
                continue
            live.discard(instruction.target.name)
            if isinstance(instruction.source, ir.Var):
                live.add(instruction.source.name)
        elif isinstance(instruction, ir.Store):
            name = instruction.target.name
            if name not in live:
                continue
            live.discard(name)
            acc_used = True
        elif isinstance(instruction, ir.StepVar):
            if instruction.target.name not in live:
                continue
        elif not acc_used:
            continue  # a load or operation whose result no one reads
        elif isinstance(instruction, ir.Compute):
            live.update(operand.name for operand in (instruction.first, instruction.second)
                        if isinstance(operand, ir.Var))
            acc_used = False
        else:
            if isinstance(instruction.source, ir.Var):
                live.add(instruction.source.name)
            acc_used = isinstance(instruction, ir.Operate)
        kept.append(instruction)
    kept.reverse()
    return kept, frozenset(live)
