"""Constant folding and propagation, across blocks.

Assumes: the IR is valid (`ir.validate`), so the accumulator is dead where a block starts.
Keeps: every call, in order, with its arguments' values; the value of every variable
after every instruction that remains; the line of every instruction that remains.

A forward data flow finds the variables whose value is known where each block starts:
all 53 are 0 where the program starts; nothing is known where a handler starts (an
event can arrive from anywhere); a call forgets the reserved variables it writes. A
branch on a known variable becomes a jump, and the path it no longer takes is not
followed, so that code behind a branch that never goes that way learns nothing from it.

Within a block, an expression whose operands are known is folded left to right with the
VM's own arithmetic (16-bit wrap, the shift rules of spec/language.md 7.2). A known
value is kept out of the accumulator until something needs it there (a store, an
operation on an unknown operand), so a folded expression costs one load at most (of the
variable the source loaded when that variable holds the value, a byte shorter than
the constant); an
operation with a known operand that changes nothing (`+0`, `|0`, `&-1`, `<0`) goes; a
store of the value the variable already holds goes; a variable argument with a known
value in its parameter's range becomes a constant (out of range, it must stay a
variable: that is a fault at run time). No path gets an instruction more, which keeps
the budget invariant (spec/optimization.md, section 3).
"""

from __future__ import annotations

from dataclasses import dataclass

from rl1.vm.language import VARIABLES
from rl1.vm.machine import evaluate

from . import forward, ir

# The operand that leaves the accumulator as it is, for each operator; 0 unless listed.
_IDENTITY = {"&": -1}
# A known accumulator that no operand changes: (value, operator).
_ABSORBING = {(0, "&"), (-1, "|"), (0, "<"), (0, ">")}

Known = dict[str, int]
"""The variables whose value is known at a point; a variable not in it is unknown."""


def fold_constants(program: ir.Program) -> ir.Program:
    zeros = _always_zero(program)
    for block_id, folded in _solve(program, zeros).items():
        block = program.blocks[block_id]  # a block no path reaches is control.py's to remove
        if isinstance(folded, _Folded):
            block.instructions = folded.instructions
        block.terminator = _terminator(block.terminator, _known_at_end(folded))
    return program


@dataclass(slots=True)
class _Folded:
    """A block whose instructions folding changed: them, and what is known where it
    ends."""

    instructions: list[ir.Instruction]
    known: Known


Visited = _Folded | Known
"""A block folded: what is known where it ends alone when its instructions stay as they
are (no object a block: a block a line of `?A<#01` held 104 bytes, 15 a source byte, of
a `_Folded` and the jump its decided branch became, which is made once the flow is
done)."""


def _known_at_end(folded: Visited) -> Known:
    return folded.known if isinstance(folded, _Folded) else folded


def _always_zero(program: ir.Program) -> frozenset[str]:
    """The variables that hold 0 wherever the flow goes, which it need not follow (its
    states are smaller, compile time): in a program without handlers (where nothing is
    known), those that nothing writes, as nothing names them."""
    if program.handlers:
        return frozenset()
    named: set[str] = set()
    for block in program:
        for instruction in block.instructions:
            match instruction:
                case ir.Call(args=args):
                    named.update(instruction.form.writes)
                    named.update(arg.name for arg in args if isinstance(arg, ir.Var))
                case ir.Load(source=ir.Var(name=name)) | ir.Operate(source=ir.Var(name=name)):
                    named.add(name)
                case ir.Store(target=target) | ir.StepVar(target=target):
                    named.add(target.name)
                case ir.Move(target=target, source=source):
                    named.update(operand.name for operand in (target, source)
                                 if isinstance(operand, ir.Var))
                case ir.Compute(first=first, second=second):
                    named.update(operand.name for operand in (first, second)
                                 if isinstance(operand, ir.Var))
        if isinstance(block.terminator, ir.Branch | ir.StoreBranch | ir.DecrementBranch):
            named.add(block.terminator.var.name)
    return frozenset(VARIABLES) - named


def _solve(program: ir.Program, zeros: frozenset[str]) -> dict[ir.BlockId, Visited]:
    """Each reachable block folded from what is known where it starts: the meet (the
    values all agree on) of what its predecessors know at their ends, and of the start
    of the program or a handler's entry. The variables in `zeros` are left out of what
    is known."""
    return forward.solve(
        program, entry={name: 0 for name in VARIABLES if name not in zeros}, handler={},
        combine=_meet, visit=lambda block, known: _fold(block, known, zeros),
        edges=_edges)


def _edges(block: ir.Block, folded: Visited) -> list[tuple[ir.BlockId, Known]]:
    """The ways the folded block goes (a branch decided goes one way), each with what
    is known where it ends."""
    known = _known_at_end(folded)
    taken = _taken(block.terminator, known)
    targets = block.terminator.targets if taken is None else (taken,)
    return [(target, known) for target in targets]


def _meet(known: Known, other: Known) -> Known:
    """What both know alike, in the first's order (deterministic, whatever
    PYTHONHASHSEED): `known` itself when the other knows all it knows."""
    if known.items() <= other.items():
        return known
    return {name: value for name, value in known.items() if other.get(name) == value}


def _value(operand: ir.Operand, known: Known) -> int | None:
    if isinstance(operand, ir.Imm):
        return operand.value
    if isinstance(operand, ir.Var):
        return known.get(operand.name)
    return None  # R: the device's answer


def _fold(block: ir.Block, entry: Known, zeros: frozenset[str]) -> Visited:
    """The block folded from what is known where it starts (`entry`, which it leaves as
    it is), and what is known where it ends: `entry` itself when the block changes
    nothing of it (one object for the blocks alike: a copy a block of a branch a line
    was 26 bytes a source byte). Its terminator is decided from that (`_terminator`)."""
    known = entry
    copied = False
    out: list[ir.Instruction] = []
    acc: int | None = None  # the accumulator's value, when known
    pending = False  # whether that known value has yet to be loaded into the accumulator
    loaded_from: ir.Var | None = None  # the variable the expression's first load named

    def writable() -> Known:
        """`known`, a copy of `entry` once it changes."""
        nonlocal known, copied
        if not copied:
            known, copied = dict(known), True
        return known

    def materialize(line: int) -> None:
        """Load the pending value: from the variable the source loaded when it holds
        the value still (LDV is a byte shorter than LDI), else as a constant."""
        nonlocal pending
        if pending:
            assert acc is not None
            holder = loaded_from if loaded_from is not None \
                and known.get(loaded_from.name) == acc else _holding(known, zeros, acc)
            out.append(ir.Load(holder or ir.Imm(acc), line))
            pending = False

    for instruction in block.instructions:
        if isinstance(instruction, ir.Load):
            source = instruction.source
            loaded_from = source if isinstance(source, ir.Var) else None
            acc = _value(source, known)
            pending = acc is not None
            if not pending:
                out.append(instruction)
        elif isinstance(instruction, ir.Operate):
            operand = _value(instruction.source, known)
            if acc is not None and operand is not None:
                acc, pending = evaluate(instruction.op, acc, operand), True
            elif operand is not None and operand == _IDENTITY.get(instruction.op, 0):
                continue  # `+0`, `|0`, `&-1`, a shift by 0: the accumulator stays
            elif pending and acc == _IDENTITY.get(instruction.op, 0) \
                    and instruction.op in "+|^&":
                out.append(ir.Load(instruction.source, instruction.line))  # `0+B` is `B`
                acc, pending = None, False
            elif pending and (acc, instruction.op) in _ABSORBING:
                continue  # `0&B`, `-1|B`, 0 shifted: the accumulator is known still
            else:
                materialize(instruction.line)
                out.append(instruction)
                acc = None
        elif isinstance(instruction, ir.Store):
            name = instruction.target.name
            if acc is not None and known.get(name) == acc:
                continue  # the variable holds this value already
            materialize(instruction.line)
            out.append(instruction)
            _set(writable(), name, acc)
        elif isinstance(instruction, ir.StepVar):
            out.append(instruction)
            name = instruction.target.name
            value = known.get(name)
            _set(writable(), name, None if value is None
                 else evaluate("+" if instruction.step == "++" else "-", value, 1))
        elif isinstance(instruction, ir.Move):
            out.append(instruction)
            _set(writable(), instruction.target.name, _value(instruction.source, known))
        elif isinstance(instruction, ir.Compute):
            out.append(instruction)  # -O2's, after this pass: left as it is
            acc, pending = None, False
        else:
            out.append(_call(instruction, known))
            for name in instruction.form.writes:
                if name in known:
                    writable().pop(name)
    if out == block.instructions:  # the block's instructions as they were: no _Folded
        return known
    return _Folded(out, known)


def _holding(known: Known, zeros: frozenset[str], value: int) -> ir.Var | None:
    """The first variable, in the language's order, that holds the value (those of
    `zeros` hold 0): one rule, so that the same source gives the same bytes."""
    if value not in known.values() and not (value == 0 and zeros):
        return None  # most often: a walk of the 53 found none
    return next((ir.Var(name) for name in VARIABLES
                 if known.get(name, 0 if name in zeros else None) == value), None)


def _set(known: Known, name: str, value: int | None) -> None:
    if value is None:
        known.pop(name, None)
    else:
        known[name] = value


def _call(call: ir.Call, known: Known) -> ir.Call:
    """The call with each variable argument whose known value its parameter accepts
    replaced by that value."""
    if all(isinstance(arg, ir.Imm) for arg in call.args):
        return call
    args: list[ir.Argument] = []
    for arg, param in zip(call.args, call.form.params, strict=True):
        value = _value(arg, known)
        in_range = value is not None and param.low <= value <= param.high
        args.append(ir.Imm(value) if in_range and value is not None else arg)
    return ir.Call(call.mnemonic, call.selector, tuple(args), call.line)


def _terminator(terminator: ir.Terminator, known: Known) -> ir.Terminator:
    """The terminator, a branch on a known variable decided: a jump."""
    taken = _taken(terminator, known)
    return terminator if taken is None else ir.Jump(taken, terminator.line)


def _taken(terminator: ir.Terminator, known: Known) -> ir.BlockId | None:
    """Where a branch on a known variable goes; None for any other terminator."""
    if not isinstance(terminator, ir.Branch):
        return None
    value = known.get(terminator.var.name)
    if value is None:
        return None
    match terminator.relation:
        case "=":
            holds = value == 0
        case ">":
            holds = value > 0
        case "<":
            holds = value < 0
    return terminator.if_true if holds else terminator.if_false
