"""Columns between the AST and the client.

The AST counts columns in code points (1-based); LSP positions count in the position
encoding negotiated at initialisation: UTF-16 code units unless the client offered
UTF-8 or UTF-32. RL/I code is ASCII, so only comments (often Japanese) make the two
differ; ASCII lines take a fast path.
"""

from __future__ import annotations

import re

from lsprotocol import types

from rl1.compiler.frontend.ast import Span

UTF8, UTF16, UTF32 = "utf-8", "utf-16", "utf-32"
_NON_ASCII = re.compile(r"[^\x00-\x7f]")


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
        self._last_text = ""
        self._last_ascii = 0

    def _ascii_prefix(self, text: str) -> int:
        """How many code points at the start of `text` are ASCII, where every encoding
        counts alike. Remembered for the last line asked about: a line's tokens are
        converted one after another, and a long line must not cost its length each."""
        if text is not self._last_text:
            found = _NON_ASCII.search(text)
            self._last_text, self._last_ascii = text, found.start() if found else len(text)
        return self._last_ascii

    def to_client(self, text: str, column: int) -> int:
        """The client column of 0-based code-point `column` in the line `text`."""
        column = min(column, len(text))
        if self.encoding == UTF32 or text.isascii():
            return column
        ascii_prefix = self._ascii_prefix(text)
        if column <= ascii_prefix:
            return column
        return ascii_prefix + sum(_width(character, self.encoding)
                                  for character in text[ascii_prefix:column])

    def from_client(self, text: str, units: int) -> int:
        """The 0-based code-point column of client column `units`, clamped to the line.
        A position inside a character (half a surrogate pair) rounds down to its start."""
        if units <= 0:
            return 0
        if self.encoding == UTF32 or text.isascii():
            return min(units, len(text))
        ascii_prefix = self._ascii_prefix(text)
        if units <= ascii_prefix:
            return units
        counted = ascii_prefix
        for column in range(ascii_prefix, len(text)):
            counted += _width(text[column], self.encoding)
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
