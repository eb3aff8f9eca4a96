"""Facts about an IR program's control flow that several passes need.

Besides the edges of the terminators, control can leave a block where a lost-line event
is taken (right after a call, right after a jump taken: spec/language.md 7.7) for a
handler block, or for a fault when the handler is missing. Those event edges exist only
in programs that can set tracing mode 2 or 3.
"""

from __future__ import annotations

from . import ir

TRACING_MODES_WITH_EVENTS = (2, 3)  # Table 4: the modes whose lost lines jump


def takes_events(program: ir.Program) -> bool:
    """Whether a lost-line event can ever reach the program: some (TRC m) sets mode 2 or
    3, or a mode held in a variable."""
    return any(
        isinstance(instruction, ir.Call) and instruction.mnemonic == "TRC"
        and (isinstance(instruction.args[0], ir.Var)
             or instruction.args[0].value in TRACING_MODES_WITH_EVENTS)
        for block in program for instruction in block.instructions
    )


def roots(program: ir.Program) -> list[ir.BlockId]:
    """Where control can enter from outside the terminators: the entry and the handlers."""
    return list(dict.fromkeys([program.entry, *program.handlers.values()]))


def reachable(program: ir.Program) -> set[ir.BlockId]:
    """The blocks some path from the entry or a handler reaches."""
    seen: set[ir.BlockId] = set()
    work = roots(program)
    while work:
        block_id = work.pop()
        if block_id in seen:
            continue
        seen.add(block_id)
        work.extend(program.successors(block_id))
    return seen


def acc_dead_after(instructions: list[ir.Instruction], index: int,
                   terminator: ir.Terminator) -> bool:
    """Whether nothing from `instructions[index]` on (the terminator included) reads
    the accumulator before loading it again."""
    for instruction in instructions[index:]:
        if isinstance(instruction, ir.Load | ir.Compute):
            return True
        if isinstance(instruction, ir.Operate | ir.Store):
            return False
    return not isinstance(terminator, ir.StoreBranch)
