"""Reads of a reserved variable (s-z) on a path where nothing has set it yet.

A must-be-set analysis, run as its complement so that the shared solver can join by `|`:
the state is the set of reserved variables that may still be unset (hold their initial
0). A call writes its reserved variables (vm/language.py), an assignment or `V++` writes its
target (W0402 has already warned about that), and a line with a syntax error is assumed
to write them all.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Callable, Iterable

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity
from rl1.vm.language import writers_of

from . import dataflow
from .effects import ALL_RESERVED, RESERVED_BIT, reserved_writes
from .graph import ControlFlowGraph

OnRead = Callable[[ast.Var], None]


def check_reserved(graph: ControlFlowGraph, on_unset: OnRead | None = None
                   ) -> list[Diagnostic]:
    """The W0401s of `graph`; with `on_unset`, each read it would report is handed to
    it instead (the streaming check holds them compactly: compact.py)."""
    blocks = graph.blocks

    # "May be unset" only shrinks, so a block's effect is `state & keep`, and a handler
    # edge's is `state & keep` up to its statement. Computed as the solver visits a
    # block: blocks no path reaches cost nothing.
    def transfer(index: int, state: int) -> tuple[int, list[tuple[int, int]]]:
        block = blocks[index]
        if block.opaque:
            return 0, []
        writes = block.effects.writes
        return state & _kept(writes, len(graph.statements(index))), [
            (edge.target, state & _kept(writes, edge.statement))
            for edge in block.handlers if edge.target is not None]

    states = dataflow.solve(graph, ALL_RESERVED, transfer)
    found: list[Diagnostic] = []

    def report(var: ast.Var) -> None:
        found.append(_unset(var))

    reported = report if on_unset is None else on_unset

    for index in itertools.compress(range(len(blocks)), states):  # in C: most states are 0
        block = blocks[index]
        state = states[index]
        reads = block.effects.reads
        if state & reads and graph.reachable(index):
            for statement in graph.statements(index):
                if not state & reads:
                    break  # the state only shrinks: no read left in the block is reported
                state = _walk(statement, state, reported)
    return found


def unset_reads(line: ast.Line, columns: Iterable[int]) -> list[Diagnostic]:
    """The W0401s of the reads in `line` at `columns`, which check_reserved reported:
    built again from the line (compact.py). A read it reported is one `_walk` reports
    from every variable unset, since its state only lacks what the calls before the read
    in the statement set, and those are left out from every state."""
    wanted = set(columns)
    found: list[Diagnostic] = []

    def report(var: ast.Var) -> None:
        if var.span.column in wanted:
            found.append(_unset(var))

    for statement in line.statements:
        _walk(statement, ALL_RESERVED, report)
    return found


def _kept(writes: list[tuple[int, int, int]], event: int) -> int:
    """The reserved variables nothing sets before the event point of statement `event`:
    the calls of that statement have run, its store has not."""
    kept = ALL_RESERVED
    for index, by_calls, by_store in writes:
        if index < event:
            kept &= ~(by_calls | by_store)
        elif index == event:
            kept &= ~by_calls
    return kept


def _walk(statement: ast.Statement, state: int, on_read: OnRead | None) -> int:
    """The state after `statement`, calling `on_read` for each read of a variable that
    may be unset, in evaluation order (left to right; the target is written last)."""
    if isinstance(statement, ast.Assign):
        state = _operand(statement.first, state, on_read)
        for step in statement.rest:
            state = _operand(step.operand, state, on_read)
        return state & ~RESERVED_BIT.get(statement.target.name, 0)
    if isinstance(statement, ast.CallStmt):
        return _operand(statement.call, state, on_read)
    if isinstance(statement, ast.IncDec):
        _read(statement.target, state, on_read)
        return state & ~RESERVED_BIT.get(statement.target.name, 0)
    if isinstance(statement, ast.CondJump):
        _read(statement.var, state, on_read)
    return state


def _operand(operand: ast.Operand, state: int, on_read: OnRead | None) -> int:
    if isinstance(operand, ast.Var):
        _read(operand, state, on_read)
    elif isinstance(operand, ast.Call):
        for arg in operand.args:
            if isinstance(arg, ast.Var):
                _read(arg, state, on_read)
        state &= ~reserved_writes(operand)
    return state


def _read(var: ast.Var, state: int, on_read: OnRead | None) -> None:
    if on_read is not None and state & RESERVED_BIT.get(var.name, 0):
        on_read(var)


def _unset(var: ast.Var) -> Diagnostic:
    message, help_text = _unset_texts(var.name)
    return Diagnostic("W0401", Severity.WARNING, message, var.span, help=help_text)


@functools.cache
def _unset_texts(name: str) -> tuple[str, str]:
    """The message and help of a W0401 on `name`: one pair of strings for every read (a
    source that reads `s` on each of a million lines held 57 bytes a source byte of
    copies of them)."""
    writers = writers_of(name)
    calls = " or ".join(f"`({builtin.mnemonic})`" for builtin, _ in writers)
    sets = "; ".join(f"`({builtin.mnemonic})` sets {', '.join(form.writes)}"
                     for builtin, form in writers)
    return (f"`{name}` is read here, but on some path no {calls} has set it yet",
            f"until then it holds 0: call {calls} before reading `{name}` ({sets})")
