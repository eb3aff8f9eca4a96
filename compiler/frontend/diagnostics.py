"""Diagnostics: what every stage reports, with a stable code, a severity and a span.

The catalogue of codes (titles and the long explanations of `rl1c explain`) lives in
`catalogue.py`; renderers for people and machines live in `render.py`.
"""

from __future__ import annotations

from enum import Enum

from .ast import Span
from .record import Record


class Severity(Enum):
    ERROR = "error"
    WARNING = "warning"
    INFO = "info"


class Edit(Record):
    """Replace the text of `span` with `text` (an empty span inserts)."""

    __slots__ = ("span", "text")
    span: Span
    text: str

    def __init__(self, span: Span, text: str) -> None:
        self.span = span
        self.text = text


class Fix(Record):
    """A machine-applicable fix: the editor's quick fix, the help line's suggestion."""

    __slots__ = ("title", "edits")
    title: str
    edits: tuple[Edit, ...]

    def __init__(self, title: str, edits: tuple[Edit, ...]) -> None:
        self.title = title
        self.edits = edits


class Related(Record):
    """Another place that explains a diagnostic (the first definition of a label...)."""

    __slots__ = ("span", "message")
    span: Span
    message: str

    def __init__(self, span: Span, message: str) -> None:
        self.span = span
        self.message = message


class Diagnostic(Record):
    __slots__ = ("code", "severity", "message", "span", "help", "fixes", "related")
    code: str
    severity: Severity
    message: str
    span: Span
    help: str | None
    fixes: tuple[Fix, ...]
    related: tuple[Related, ...]

    def __init__(self, code: str, severity: Severity, message: str, span: Span,
                 help: str | None = None, fixes: tuple[Fix, ...] = (),
                 related: tuple[Related, ...] = ()) -> None:
        self.code = code
        self.severity = severity
        self.message = message
        self.span = span
        self.help = help
        self.fixes = fixes
        self.related = related

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR


def sort_key(diagnostic: Diagnostic) -> tuple[int, int, str]:
    return (diagnostic.span.line, diagnostic.span.column, diagnostic.code)
