"""The front end in one call: source text to AST and sorted diagnostics."""

from __future__ import annotations

from .checker import check
from .frontend.ast import Program
from .frontend.diagnostics import Diagnostic, sort_key
from .frontend.parser import parse_program
from .frontend.record import Record


class Analysis(Record):
    __slots__ = ("program", "diagnostics")
    program: Program
    diagnostics: list[Diagnostic]

    def __init__(self, program: Program, diagnostics: list[Diagnostic]) -> None:
        self.program = program
        self.diagnostics = diagnostics

    @property
    def has_errors(self) -> bool:
        return any(diagnostic.is_error for diagnostic in self.diagnostics)


def analyze(text: str) -> Analysis:
    program, diagnostics = parse_program(text)
    diagnostics.extend(check(program))
    diagnostics.sort(key=sort_key)
    return Analysis(program, diagnostics)
