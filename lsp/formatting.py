"""Formatting with the project's formatter: the whole document, or a range of lines."""

from __future__ import annotations

from lsprotocol import types

from rl1.compiler.formatter import format_lines, format_text

from .document import Document
from .positions import Columns


def format_document(document: Document, columns: Columns) -> list[types.TextEdit]:
    """One edit replacing the document, or none when it is already canonical."""
    text = document.text()
    formatted = format_text(text)
    if formatted == text:
        return []
    whole = types.Range(types.Position(0, 0), document.end_position(columns))
    return [types.TextEdit(range=whole, new_text=formatted)]


def format_range(document: Document, requested: types.Range,
                 columns: Columns) -> list[types.TextEdit]:
    """Edits for each line the range touches; a range ending at the start of a line
    does not take that line in."""
    last = requested.end.line + (0 if requested.end.character == 0 and
                                 requested.end.line > requested.start.line else 1)
    return [
        types.TextEdit(range=document.range_of(edit.span, columns), new_text=edit.text)
        for edit in format_lines(document.text(), requested.start.line + 1, last)
    ]
