"""Helpers for the checker's tests: run the front end, pick diagnostics, apply fixes."""

from __future__ import annotations

from collections.abc import Sequence

from hypothesis import strategies as st

from rl1.compiler.analysis import analyze
from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Edit, Fix

FIX_TEXTS = ["", "Z", "\n(END)", "; "]  # what an edit writes: nothing, a word, a line


def found(source: str, code: str) -> list[Diagnostic]:
    """The diagnostics of `source` with `code`."""
    return [d for d in analyze(source).diagnostics if d.code == code]


def one(source: str, code: str) -> Diagnostic:
    """The one diagnostic of `source` with `code` (the test fails if there are more)."""
    matches = found(source, code)
    assert len(matches) == 1, [(d.code, d.span, d.message) for d in matches]
    return matches[0]


def codes(source: str) -> list[str]:
    return [d.code for d in analyze(source).diagnostics]


def span(line: int, column: int, end_column: int, end_line: int | None = None) -> Span:
    return Span(line, column, line if end_line is None else end_line, end_column)


def apply(source: str, fix: Fix) -> str:
    """`source` with the edits of `fix` made (spans are 1-based lines and columns)."""
    lines = source.split("\n")
    starts = [0]
    for text in lines:
        starts.append(starts[-1] + len(text) + 1)

    def offset(line: int, column: int) -> int:
        return starts[line - 1] + column - 1

    for edit in sorted(fix.edits, key=lambda e: (e.span.line, e.span.column), reverse=True):
        start = offset(edit.span.line, edit.span.column)
        end = offset(edit.span.end_line, edit.span.end_column)
        source = source[:start] + edit.text + source[end:]
    return source


@st.composite
def an_edit(draw: st.DrawFn, texts: Sequence[str]) -> Edit:
    """An edit in the first lines of a short source, writing one of `texts`; its span
    may end past its line or the text, as a fix's may."""
    line = draw(st.integers(1, 6))
    column = draw(st.integers(1, 8))
    end_line = draw(st.integers(line, 7))
    end_column = draw(st.integers(1 if end_line > line else column, 9))
    return Edit(Span(line, column, end_line, end_column), draw(st.sampled_from(texts)))
