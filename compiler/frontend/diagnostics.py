"""Diagnostics: what every stage reports, with a stable code, a severity and a span.

The catalogue of codes (titles and the long explanations of `rl1c explain`) lives in
`catalogue.py`; renderers for people and machines live in `render.py`.
"""

from __future__ import annotations

from enum import Enum
from operator import attrgetter
from typing import NamedTuple

from .ast import Span


class Severity(Enum):
    ERROR = "error"
    WARNING = "warning"
    INFO = "info"


class Edit(NamedTuple):
    """Replace the text of `span` with `text` (an empty span inserts)."""

    span: Span
    text: str


class Fix(NamedTuple):
    """A machine-applicable fix: the editor's quick fix, the help line's suggestion.
    `safe` (ruff's model, spec/language.md section 5.8): the program after it means what
    the text before it already meant, and keeps every label and statement written, so
    `rl1c check --fix` and the editor's "fix all" make it; an unsafe fix (a guess at a
    misspelt name, a removal, a change of what the vehicle does) is made only when
    asked (`--unsafe-fixes`, or the one quick fix)."""

    title: str
    edits: tuple[Edit, ...]
    safe: bool = False


class Related(NamedTuple):
    """Another place that explains a diagnostic (the first definition of a label...)."""

    span: Span
    message: str


class Diagnostic(NamedTuple):
    code: str
    severity: Severity
    message: str
    span: Span
    help: str | None = None
    fixes: tuple[Fix, ...] = ()
    related: tuple[Related, ...] = ()

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR


def sort_key(diagnostic: Diagnostic) -> tuple[int, int, str]:
    return (diagnostic.span.line, diagnostic.span.column, diagnostic.code)


# sort_key's parts, last first, each an object the diagnostic already holds
_PLACE_PARTS = (attrgetter("code"), attrgetter("span.column"), attrgetter("span.line"))


def sort_by_place(diagnostics: list[Diagnostic]) -> None:
    """Sort `diagnostics` in place into sort_key's order (equal keys keep their order)
    without a key tuple a diagnostic, which a source of a syntax error a line would
    hold 9 bytes a source byte of while sorting (bench/memory.py): stable sorts by each
    part of the key, the last first, whose keys the diagnostics hold already."""
    for part in _PLACE_PARTS:
        diagnostics.sort(key=part)
