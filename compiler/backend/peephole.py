"""Peephole rewrites to cheaper instructions: `A=A+1` to `INC A`, `A=A-1` to `DEC A`.

Assumes: the IR is valid (the accumulator is dead where a block starts).
Keeps: the value of every variable after every statement; every call.

`load A; add k; store A` with k one of -2..2 (or `sub k`) becomes |k| steps of A when
nothing after it reads the accumulator before loading it again: the steps leave the
accumulator alone, so it no longer holds A's new value. Two steps are two instructions
where the three were, so no path gets longer.
"""

from __future__ import annotations

from rl1.compiler.frontend.ast import Step

from . import flow, ir

MAX_STEPS = 2  # +-3 would take as many instructions as the load-add-store


def rewrite_steps(program: ir.Program) -> ir.Program:
    for block in program:
        block.instructions = _with_steps(block.instructions, block.terminator)
    return program


def _with_steps(instructions: list[ir.Instruction], terminator: ir.Terminator
                ) -> list[ir.Instruction]:
    out: list[ir.Instruction] = []
    index = 0
    while index < len(instructions):
        steps = _steps_at(instructions, index, terminator)
        if steps is None:
            out.append(instructions[index])
            index += 1
        else:
            out.extend(steps)
            index += 3
    return out


def _steps_at(instructions: list[ir.Instruction], index: int, terminator: ir.Terminator
              ) -> list[ir.StepVar] | None:
    window = instructions[index:index + 3]
    if len(window) < 3:
        return None
    load, operate, store = window
    if not (isinstance(load, ir.Load) and isinstance(operate, ir.Operate)
            and isinstance(store, ir.Store) and isinstance(load.source, ir.Var)
            and load.source == store.target and isinstance(operate.source, ir.Imm)
            and operate.op in "+-" and flow.acc_dead_after(instructions, index + 3, terminator)):
        return None
    delta = operate.source.value if operate.op == "+" else -operate.source.value
    if delta == 0 or abs(delta) > MAX_STEPS:
        return None
    step: Step = "++" if delta > 0 else "--"
    return [ir.StepVar(store.target, step, store.line)] * abs(delta)
