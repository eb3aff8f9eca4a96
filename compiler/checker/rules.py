"""The whole-program rules, in the order their diagnostics are listed, over a program's
graph and its span (where a fix adds a line at the end)."""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic

from .graph import ControlFlowGraph
from .handlers import check_handlers
from .labels import OnUndefined, check_labels
from .loops import check_loops
from .reachability import check_reachability
from .reserved import OnRead, check_reserved
from .safety import check_safety


def check_graph(graph: ControlFlowGraph, program: ast.Span, on_unset: OnRead | None = None,
                on_undefined: OnUndefined | None = None) -> list[Diagnostic]:
    """The diagnostics of the whole-program rules on `graph`, whose program spans
    `program`; with `on_unset`, the reads W0401 reports are handed to it instead, and
    with `on_undefined` the targets E0203 reports."""
    return [
        *check_labels(graph, on_undefined),
        *check_handlers(program, graph),
        *check_reserved(graph, on_unset),
        *check_reachability(program, graph),
        *check_loops(graph),
        *check_safety(program, graph),
    ]
