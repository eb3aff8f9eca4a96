"""Superinstructions (-O2): pairs of instructions the corpus runs often, fused into the
instructions of format 1.FUSED_MINOR (vm/isa.py).

Assumes: the IR is valid and the -O1 passes are done (this pass runs once, last: the
other passes know nothing of what it makes).
Keeps: every variable's value after every statement; every call; the jumps taken (a
fused jump is a jump, where the budget is checked and an event taken); no path longer.

- `store V` then a branch on V (`A=(IMG)-180; ?A<#10`) becomes one store-and-branch,
  also when stores of other variables, or moves and steps that neither read nor write V,
  come between (`E=I-P; P=I; ?E>#20`: the store of E goes after the move, which leaves
  the accumulator as it is).
- `dec V` then a branch on V > 0 (`@--; ?@>#14`, a counted loop) becomes one
  decrement-and-branch, also past instructions that neither read nor write V (`@--;
  A=B; ?@>#10`). No call comes between in either case: a call sees the variables, and
  can fault.
- `load x` then stores of it, when nothing reads the accumulator after them, become
  moves (`A=B`, `A=5`, `A=(IMG)`): one instruction per store instead of one more (the
  code generator writes a constant move as MOVB, a byte shorter, when it fits a byte).
- `load x` then an operation on y, x a variable or R and y a variable or a constant,
  become one load-and-operate (`E=L-M`, `A=(IMG)-180`): an expression's first two
  operands in one instruction. (A constant first is folded by -O1 or stays: `0-M`.)
  A load whose value is also stored before the operation (`D=(ULT A); E=D-G`) becomes
  the moves, then the load-and-operate: one instruction fewer again; also when calls
  or steps that leave the accumulator and the load's source as they are come between
  (`I=(INP 2); (LMP 0); E=I-128`, where copy propagation dropped the load of I).
- A call whose constant arguments each fit a byte (`MOV 4,4`, `TRC 30`) becomes a compact
  call (format 1.3): a byte an argument instead of two.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import takewhile

from . import flow, ir


def fuse(program: ir.Program) -> ir.Program:
    for block in program:
        _fuse_branch(block)
        block.instructions = _moves(block.instructions, block.terminator)
        _fuse_branch(block)  # again, past the moves just made (`E=I-P; P=I; ?E>#20`)
        block.instructions = [_compact(instruction) for instruction in
                              _computes(block.instructions)]
    return program


def _compact(instruction: ir.Instruction) -> ir.Instruction:
    if isinstance(instruction, ir.Call) and instruction.args and all(
            not isinstance(arg, ir.Imm) or -0x80 <= arg.value <= 0x7F
            for arg in instruction.args):
        return replace(instruction, compact=True)
    return instruction


def _reload(load: ir.Load, stores: list[ir.Instruction], following: list[ir.Instruction]
            ) -> ir.Var | ir.Result | None:
    """What the load can come again from after its stores became moves, to fuse with the
    operation after them and after the calls and steps `_between` them: its source, or
    else a variable it was stored into, that those leave as it is. None when no such
    operation makes a load-and-operate (so that the load costs nothing), or a store
    changes the source."""
    between = _between(following)
    operation = following[len(between):][:1]
    if not (isinstance(load.source, ir.Var | ir.Result)
            and all(isinstance(store, ir.Store) and store.target != load.source
                    for store in stores)
            and operation and isinstance(operation[0], ir.Operate)
            and isinstance(operation[0].source, ir.Var | ir.Imm)):
        return None
    holders = [load.source, *(store.target for store in stores if isinstance(store, ir.Store))]
    return next((holder for holder in holders
                 if all(_keeps(instruction, holder) for instruction in between)), None)


def _between(following: list[ir.Instruction]) -> list[ir.Instruction]:
    """The calls and steps at the start of `following`: they leave the accumulator as
    it is."""
    return list(takewhile(lambda instruction: isinstance(instruction, ir.Call | ir.StepVar),
                          following))


def _keeps(instruction: ir.Instruction, holder: ir.Var | ir.Result) -> bool:
    """Whether a call or step leaves what `holder` holds (R is the last call's only
    until another call: ir.validate)."""
    match instruction, holder:
        case ir.Call(), ir.Var(name=name):
            return name not in instruction.form.writes
        case ir.StepVar(target=target), _:
            return target != holder
        case _:
            return False


def _computes(instructions: list[ir.Instruction]) -> list[ir.Instruction]:
    out: list[ir.Instruction] = []
    for instruction in instructions:
        load = out[-1] if out else None
        if (isinstance(instruction, ir.Operate) and isinstance(load, ir.Load)
                and isinstance(load.source, ir.Var | ir.Result)
                and isinstance(instruction.source, ir.Var | ir.Imm)):
            out[-1] = ir.Compute(load.source, instruction.op, instruction.source, load.line)
        else:
            out.append(instruction)
    return out


def _fuse_branch(block: ir.Block) -> None:
    """The branch fused with the last instruction of the block that mentions its
    variable, when that is a store of it (or a decrement, for a branch on > 0) and no
    call comes after it (a call sees every variable, and can fault): what follows it
    neither reads nor writes the variable, so it can go before the write; past a store,
    it must also leave the accumulator as it is."""
    branch = block.terminator
    if not isinstance(branch, ir.Branch):
        return
    instructions = block.instructions
    index = next((index for index in reversed(range(len(instructions)))
                  if isinstance(instructions[index], ir.Call)
                  or branch.var in ir.operands(instructions[index])), None)
    if index is None:
        return
    write, after = instructions[index], instructions[index + 1:]
    if isinstance(write, ir.Store) and write.target == branch.var and all(
            isinstance(instruction, ir.Store | ir.Move | ir.StepVar) for instruction in after):
        block.terminator = ir.StoreBranch(branch.var, branch.relation, branch.if_true,
                                          branch.if_false, branch.line)
    elif isinstance(write, ir.StepVar) and write.target == branch.var \
            and write.step == "--" and branch.relation == ">":
        block.terminator = ir.DecrementBranch(branch.var, branch.if_true, branch.if_false,
                                              branch.line)
    else:
        return
    block.instructions = [*instructions[:index], *after]


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
        reload = None
        if not (isinstance(load, ir.Load) and stores and (
                flow.acc_dead_after(instructions, end, terminator)
                or (reload := _reload(load, stores, instructions[end:])) is not None)):
            out.append(load)
            index += 1
            continue
        out += [ir.Move(store.target, load.source, store.line)
                for store in stores if isinstance(store, ir.Store)]
        if reload is not None:
            # `D=(ULT A); E=D-G`: moves, then the load fuses on with the operation, on
            # that operation's line (the stores' lines came after the load's);
            # `I=(INP 2); (LMP 0); E=I-128`: after the call, from I
            between = _between(instructions[end:])
            out += between
            end += len(between)
            out.append(ir.Load(reload, instructions[end].line))
        index = end
    return out
