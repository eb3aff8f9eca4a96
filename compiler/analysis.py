"""The front end in one call: source text to AST and sorted diagnostics."""

from __future__ import annotations

from dataclasses import dataclass

from .checker import check
from .frontend.ast import Program
from .frontend.diagnostics import Diagnostic, sort_key
from .frontend.parser import parse_program


@dataclass(frozen=True, slots=True, eq=False)
class Analysis:
    program: Program
    diagnostics: list[Diagnostic]

    @property
    def has_errors(self) -> bool:
        return any(diagnostic.is_error for diagnostic in self.diagnostics)


def analyze(text: str) -> Analysis:
    program, diagnostics = parse_program(text)
    diagnostics.extend(check(program))
    diagnostics.sort(key=sort_key)
    return Analysis(program, diagnostics)
