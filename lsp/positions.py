"""Columns between the AST and the client.

The AST counts columns in code points (1-based); LSP positions count in the position
encoding negotiated at initialisation: UTF-16 code units unless the client offered
UTF-8 or UTF-32. RL/I code is ASCII, so only comments (often Japanese) make the two
differ; ASCII lines take a fast path.
"""

from __future__ import annotations

from lsprotocol import types

from rl1.compiler.ast import Span

UTF8, UTF16, UTF32 = "utf-8", "utf-16", "utf-32"


def _width(character: str, encoding: str) -> int:
    """How many code units of `encoding` one code point takes."""
    point = ord(character)
    if encoding == UTF16:
        return 2 if point > 0xFFFF else 1
    if point < 0x80:
        return 1
    if point < 0x800:
        return 2
    return 3 if point < 0x10000 else 4  # lone surrogates count 3, as surrogatepass writes


class Columns:
    """Converts between code-point columns and client columns for one encoding."""

    def __init__(self, encoding: str = UTF16) -> None:
        if encoding not in (UTF8, UTF16, UTF32):
            raise ValueError(f"unsupported position encoding {encoding!r}")
        self.encoding = encoding

    def to_client(self, text: str, column: int) -> int:
        """The client column of 0-based code-point `column` in the line `text`."""
        column = min(column, len(text))
        if self.encoding == UTF32 or text.isascii():
            return column
        return sum(_width(character, self.encoding) for character in text[:column])

    def from_client(self, text: str, units: int) -> int:
        """The 0-based code-point column of client column `units`, clamped to the line.
        A position inside a character (half a surrogate pair) rounds down to its start."""
        if units <= 0:
            return 0
        if self.encoding == UTF32 or text.isascii():
            return min(units, len(text))
        counted = 0
        for column, character in enumerate(text):
            counted += _width(character, self.encoding)
            if counted > units:
                return column
        return len(text)

    def length(self, text: str) -> int:
        """The length of `text` in client units."""
        return self.to_client(text, len(text))


def span_range(span: Span, line_text: str, end_line_text: str, columns: Columns) -> types.Range:
    """The LSP range of an AST span; the texts are those of its first and last lines."""
    start = columns.to_client(line_text, span.column - 1)
    end = columns.to_client(end_line_text, span.end_column - 1)
    return types.Range(types.Position(span.line - 1, start), types.Position(span.end_line - 1, end))
