"""Branches decided by signs: what earlier branches (and loads of constants, masks, and
the calls' result ranges) proved about each variable's sign.

Assumes: the IR is valid (the accumulator is dead where a block starts).
Keeps: every instruction; every call; the value of every variable everywhere; the order
of the blocks that remain; no path longer (spec/optimization.md, section 3).

A forward data flow finds, where each block starts, the signs (`<`, `=`, `>`: negative,
zero, positive) each variable may have: only `=` for all 53 where the program starts,
any where a handler starts; a branch's taken edge keeps only its relation, its other
edge all but it. Then:

- A branch whose variable can only have signs its relation holds for becomes a jump to
  its target, and one whose variable can have none of them a jump past it (after
  `?H=#20` falls through, `?H=#30` is a jump on).
- A branch to the block laid out next whose other way is a jump (`?N=#20; #10` with
  `:20` next: a conditional, then a `JMP` on every way round), when every sign but the
  branch's that the variable may have is one relation, becomes the branch on that
  relation to where the jump went, falling through to the old target: as Lua's
  `luaK_goiftrue` negates a test instead of jumping around a jump. The instruction set
  has only `=`, `>` and `<` (no "not zero"), so this needs what the flow proved:
  `?N=#20; #10` with N known not negative is `?N>#10`. The way that jumped runs one
  instruction fewer, the other as many as before.
- A way into a block that holds only a branch, when what that way proved decides the
  branch (`?V>#12` after `V=6; #11`), goes straight to where the branch would go,
  unless that way falls through (the jump it would need costs as much as the branch).
"""

from __future__ import annotations

import dataclasses
import itertools
from functools import cache

from rl1.compiler.frontend.ast import Relation
from rl1.vm.language import VARIABLES

from . import forward, ir

Signs = frozenset[str]
"""The signs a value may have: a subset of `<`, `=`, `>` (the relations with zero)."""

ANY: Signs = frozenset("<=>")
_ONLY: dict[str, Signs] = {relation: frozenset(relation) for relation in ANY}
NOT_NEGATIVE: Signs = frozenset("=>")
State = dict[str, Signs]
"""Each variable whose sign is known to be limited; a variable not in it may have any."""

# What a step does to each sign: 0 + 1 is positive, 32767 + 1 wraps to -32768.
_STEPPED: dict[str, dict[str, Signs]] = {
    "++": {"<": frozenset("<="), "=": frozenset(">"), ">": frozenset("<>")},
    "--": {">": frozenset("=>"), "=": frozenset("<"), "<": frozenset("<>")},
}


def decide_branches(program: ir.Program) -> ir.Program:
    # the blocks that only branch, as they are before any is rewritten
    branches = {block.id: block.terminator for block in program
                if not block.instructions and isinstance(block.terminator, ir.Branch)}
    exits = _solve(program, _tracked(program))
    # Each block with the one laid out after it, where it falls through (no dictionary
    # of them: 7 bytes a source byte of a branch a line).
    laid_out_next = itertools.chain(itertools.islice(program, 1, None), [None])
    for block, after in zip(program, laid_out_next, strict=True):
        state = exits.get(block.id)
        if state is None:
            continue  # no path reaches it: control.py's to remove
        following = after.id if after is not None else None
        if isinstance(block.terminator, ir.Branch):
            block.terminator = _rewritten(block.terminator, state, following)
        block.terminator = _threaded(block.terminator, state, branches, following)
    return program


def _threaded(terminator: ir.Terminator, state: State,
              branches: dict[ir.BlockId, ir.Branch], following: ir.BlockId | None
              ) -> ir.Terminator:
    """The terminator with each way into a block that only branches, where what the
    way proves decides that branch, going straight on to where it goes, unless the way
    falls through (a jump in place of the branch it skips would cost as many
    instructions and three bytes more)."""
    def past(target: ir.BlockId, leaving: State) -> ir.BlockId:
        branch = branches.get(target)
        if branch is None or target == following:
            return target
        decided = _decided(branch, leaving.get(branch.var.name, ANY))
        return target if decided is None else decided

    match terminator:
        case ir.Jump(target=target) if target in branches:
            onward = past(target, state)
            if onward != target:
                return dataclasses.replace(terminator, target=onward)
        case ir.Branch(var=var, relation=relation, if_true=if_true, if_false=if_false) \
                if if_true in branches or if_false in branches:
            signs = state.get(var.name, ANY)
            ways = (past(if_true, {**state, var.name: frozenset(relation)}),
                    past(if_false, {**state, var.name: signs - {relation}}))
            if ways != (if_true, if_false):
                return dataclasses.replace(terminator, if_true=ways[0], if_false=ways[1])
    return terminator  # as it was: no way into a block that only branches is decided


def _rewritten(branch: ir.Branch, state: State, following: ir.BlockId | None
               ) -> ir.Terminator:
    """The branch decided, or negated so that its jump falls through, or as it was."""
    signs = state.get(branch.var.name, ANY)
    decided = _decided(branch, signs)
    if decided is not None:
        return ir.Jump(decided, branch.line)
    others = signs - {branch.relation}
    if branch.if_true == following and branch.if_false != following and len(others) == 1:
        # `JLT N :20; JMP :10` with :20 next: one conditional jump to :10 does it.
        relation: Relation = "=" if "=" in others else ">" if ">" in others else "<"
        return ir.Branch(branch.var, relation, branch.if_false, branch.if_true, branch.line)
    return branch


def _decided(branch: ir.Branch, signs: Signs) -> ir.BlockId | None:
    """Where the branch goes when a variable of these signs decides it."""
    if signs <= {branch.relation}:
        return branch.if_true
    if branch.relation not in signs:
        return branch.if_false
    return None


def _tracked(program: ir.Program) -> frozenset[str]:
    """The variables whose signs can matter: those branched on, and those loaded or
    moved (whose signs a store can pass on). Following only them keeps the flow's
    states small (most programs branch on a few of the 53)."""
    names: set[str] = set()
    for block in program:
        if isinstance(block.terminator, ir.Branch):
            names.add(block.terminator.var.name)
        for instruction in block.instructions:
            match instruction:
                case ir.Load(source=ir.Var(name=name)) | ir.Move(source=ir.Var(name=name)):
                    names.add(name)
    return frozenset(names)


def _solve(program: ir.Program, tracked: frozenset[str]) -> dict[ir.BlockId, State]:
    """What is known where each block some path reaches ends (before its terminator),
    from what is known where it starts: the union (the signs any path allows) over its
    predecessors' edges and the program's or a handler's start. A decided branch's
    other edge is not followed."""
    entry = dict.fromkeys([name for name in VARIABLES if name in tracked], frozenset("="))
    return forward.solve(program, entry=entry, handler={}, combine=_join,
                         visit=lambda block, state: _exit_state(block, state, tracked),
                         edges=_edges)


def _join(state: State, other: State) -> State:
    """The signs either state allows, in the first's order (deterministic): `state`
    itself when the other allows no sign it does not."""
    joined: State = {}
    for name, signs in state.items():
        others = other.get(name)
        if others is not None:
            union = signs | others
            if union != ANY:
                joined[name] = union
    return state if joined == state else joined


def _edges(block: ir.Block, state: State) -> list[tuple[ir.BlockId, State]]:
    terminator = block.terminator
    if isinstance(terminator, ir.StoreBranch | ir.DecrementBranch):
        forgotten = {name: signs for name, signs in state.items()
                     if name != terminator.var.name}
        return [(target, forgotten) for target in terminator.targets]
    if not isinstance(terminator, ir.Branch):
        return [(target, state) for target in terminator.targets]
    name = terminator.var.name
    signs = state.get(name, ANY)
    decided = _decided(terminator, signs)
    if decided is not None:
        return [(decided, state)]
    return [(terminator.if_true, {**state, name: _ONLY[terminator.relation]}),
            (terminator.if_false, {**state, name: signs - _ONLY[terminator.relation]})]


def _exit_state(block: ir.Block, entry: State, tracked: frozenset[str]) -> State:
    """What is known where the block ends, from `entry`, which it leaves as it is: `entry`
    itself when no instruction writes a variable the flow follows (one object for the
    blocks alike: a copy a block of a branch a line was 9 bytes a source byte)."""
    state = entry
    copied = False

    def write(name: str, signs: Signs) -> None:
        """The variable's signs set, in a copy of `entry` once one changes."""
        nonlocal state, copied
        if name not in tracked:
            return
        if not copied:
            state, copied = dict(state), True
        if signs == ANY:
            state.pop(name, None)
        else:
            state[name] = signs

    acc: Signs = ANY
    result: Signs = ANY  # R's signs, from the last call's result range
    for instruction in block.instructions:
        match instruction:
            case ir.Load(source=source):
                acc = _operand(source, state, result)
            case ir.Operate(op="&", source=source):
                if acc <= NOT_NEGATIVE or _operand(source, state, result) <= NOT_NEGATIVE:
                    acc = NOT_NEGATIVE  # a mask with the sign bit clear
                else:
                    acc = ANY
            case ir.Operate():
                acc = ANY
            case ir.Store(target=target):
                write(target.name, acc)
            case ir.StepVar(target=target, step=step):
                before = state.get(target.name, ANY)
                write(target.name, frozenset().union(*(_STEPPED[step][sign] for sign in before)))
            case ir.Move(target=target, source=source):
                write(target.name, _operand(source, state, result))
            case ir.Compute():
                acc = ANY
            case ir.Call():
                form = instruction.form
                for name in form.writes:
                    write(name, ANY)
                result = _result_signs(form.result_range)
    return state


@cache
def _result_signs(result_range: tuple[int, int]) -> Signs:
    low, high = result_range
    return frozenset(sign for sign, present in
                     (("<", low < 0), ("=", low <= 0 <= high), (">", high > 0)) if present)


_SIGN_OF = {-1: frozenset("<"), 0: frozenset("="), 1: frozenset(">")}


def _operand(operand: ir.Operand, state: State, result: Signs) -> Signs:
    match operand:
        case ir.Imm(value=value):
            return _SIGN_OF[(value > 0) - (value < 0)]
        case ir.Var(name=name):
            return state.get(name, ANY)
        case _:
            return result
