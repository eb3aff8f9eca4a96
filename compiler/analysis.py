"""The front end in one call: source text to AST and sorted diagnostics (those the
program's comments allow left out); `fix` makes the checker's fixes."""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

from .checker import apply_suppressions, check
from .frontend.ast import Program
from .frontend.diagnostics import Diagnostic, sort_key
from .frontend.edits import apply_edits, compatible
from .frontend.parser import parse_program


class Analysis(NamedTuple):
    program: Program
    diagnostics: list[Diagnostic]

    @property
    def has_errors(self) -> bool:
        return any(diagnostic.is_error for diagnostic in self.diagnostics)


def analyze(text: str) -> Analysis:
    program, diagnostics = parse_program(text)
    diagnostics.extend(check(program))
    diagnostics = apply_suppressions(program, diagnostics)
    diagnostics.sort(key=sort_key)
    return Analysis(program, diagnostics)


MAX_FIX_ROUNDS = 10
"""Rounds of fixing before `fix` gives up: one fix can bring out another (an added
`(END)` that the vehicle reaches still moving), and fixes at one place wait a round."""


class Fixed(NamedTuple):
    """The text with the fixes made, how many were made, and its analysis."""

    text: str
    fixes: int
    analysis: Analysis


def fix(text: str, keep: Callable[[Diagnostic], bool] = lambda _: True) -> Fixed:
    """`text` with the automatic fixes of the diagnostics `keep` accepts made, round
    after round, until no such fix is left (or MAX_FIX_ROUNDS)."""
    analysis = analyze(text)
    made = 0
    for _ in range(MAX_FIX_ROUNDS):
        fixes = compatible(next(f for f in d.fixes if f.automatic) for d in analysis.diagnostics
                           if keep(d) and any(f.automatic for f in d.fixes))
        if not fixes:
            break
        text = apply_edits(text, [edit for one in fixes for edit in one.edits])
        made += len(fixes)
        analysis = analyze(text)
    return Fixed(text, made, analysis)
