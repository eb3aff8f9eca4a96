"""The static checker: the per-line rules (lines.py), then the whole-program rules
(rules.py) over the control-flow graph (graph.py, built by cfg.py) and the data-flow
analyses on it; `apply_suppressions` (suppression.py) then drops the warnings the
program's comments allow. `check_text` (streaming.py) does it all on a source text
without holding its tree."""

from __future__ import annotations

from rl1.compiler.frontend.ast import Program
from rl1.compiler.frontend.collector import collector_paused
from rl1.compiler.frontend.diagnostics import Diagnostic

from .cfg import build_cfg
from .graph import ControlFlowGraph
from .incremental import LineMemo
from .lines import check_line
from .rules import check_graph
from .streaming import check_text
from .suppression import apply_suppressions

__all__ = ["ControlFlowGraph", "LineMemo", "apply_suppressions", "build_cfg", "check",
           "check_line", "check_program", "check_text"]


def check(program: Program) -> list[Diagnostic]:
    """Every diagnostic of the static rules, in no particular order."""
    found: list[Diagnostic] = []
    with collector_paused():
        for line in program.lines:
            found.extend(check_line(line))
        found.extend(check_program(program))
    return found


def check_program(program: Program, memo: LineMemo | None = None) -> list[Diagnostic]:
    """The diagnostics of the whole-program rules only (the language server combines
    them with its cached per-line results, and passes a memo of the lines it keeps)."""
    return check_graph(build_cfg(program, memo), program.span)
