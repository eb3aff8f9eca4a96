"""Diagnostics: what every stage reports, with a stable code, a severity and a span.

The catalogue of codes (titles and the long explanations of `rl1c explain`) lives in
`catalogue.py`; renderers for people and machines live in `render.py`.
"""

from __future__ import annotations

from enum import Enum
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
    `automatic` is False for a guess (a misspelt name's closest match), which
    `rl1c check --fix` leaves for a person to confirm."""

    title: str
    edits: tuple[Edit, ...]
    automatic: bool = True


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
