"""Superinstructions (-O2): pairs of instructions the corpus runs often, fused into the
instructions of format 1.FUSED_MINOR (vm/isa.py).

Assumes: the IR is valid and the -O1 passes are done (this pass runs once, last: the
other passes know nothing of what it makes).
Keeps: every variable's value after every statement; every call; the jumps taken (a
fused jump is a jump, where the budget is checked and an event taken); no path longer.

- `store V` then a branch on V (`A=(IMG)-180; ?A<#10`) becomes one store-and-branch.
- `dec V` then a branch on V > 0 (`@--; ?@>#14`, a counted loop) becomes one
  decrement-and-branch.
- `load x` then stores of it, when nothing reads the accumulator after them, become
  moves (`A=B`, `A=5`, `A=(IMG)`): one instruction per store instead of one more.
"""

from __future__ import annotations

from . import flow, ir


def fuse(program: ir.Program) -> ir.Program:
    for block in program:
        _fuse_branch(block)
        block.instructions = _moves(block.instructions, block.terminator)
    return program


def _fuse_branch(block: ir.Block) -> None:
    branch = block.terminator
    if not isinstance(branch, ir.Branch) or not block.instructions:
        return
    last = block.instructions[-1]
    if isinstance(last, ir.Store) and last.target == branch.var:
        block.instructions = block.instructions[:-1]
        block.terminator = ir.StoreBranch(branch.var, branch.relation, branch.if_true,
                                          branch.if_false, branch.line)
    elif (isinstance(last, ir.StepVar) and last.target == branch.var and last.step == "--"
            and branch.relation == ">"):
        block.instructions = block.instructions[:-1]
        block.terminator = ir.DecrementBranch(branch.var, branch.if_true, branch.if_false,
                                              branch.line)


def _moves(instructions: list[ir.Instruction], terminator: ir.Terminator
           ) -> list[ir.Instruction]:
    out: list[ir.Instruction] = []
    index = 0
    while index < len(instructions):
        load = instructions[index]
        end = index + 1
        while end < len(instructions) and isinstance(instructions[end], ir.Store):
            end += 1
        stores = instructions[index + 1:end]
        if (isinstance(load, ir.Load) and stores
                and flow.acc_dead_after(instructions, end, terminator)):
            out += [ir.Move(store.target, load.source, store.line)
                    for store in stores if isinstance(store, ir.Store)]
            index = end
        else:
            out.append(load)
            index += 1
    return out
