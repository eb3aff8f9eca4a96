"""Reading RL/I source: bytes to text, and text to lines.

Source is UTF-8; legacy files whose comments are Shift-JIS (CP932) are read too. Lines end
with LF, CRLF or a lone CR, exactly as the Language Server Protocol counts them.
"""

from __future__ import annotations

import re
from array import array
from collections.abc import Iterator
from typing import NamedTuple

from rl1.compiler.files import SourceError, read_bounded

from .scanner import WHITESPACE

MAX_SOURCE_BYTES = 8 * 1024 * 1024  # compiling takes up to 160 bytes a byte: bench/memory.py
UTF8_BOM = b"\xef\xbb\xbf"
LINE_BREAK = re.compile(r"\r\n|\r|\n")
"""A line end: LF, CRLF or a lone CR, exactly as the Language Server Protocol counts them."""


class Source(NamedTuple):
    name: str
    text: str
    encoding: str  # "utf-8" or "cp932"
    bom: bool = False  # the UTF-8 byte-order mark the file started with, dropped from text

    @property
    def lines(self) -> list[str]:
        return split_lines(self.text)


def split_lines(text: str) -> list[str]:
    """The lines of `text` without their line ends. A final line end does not start an
    extra line; an empty text has no lines."""
    lines = LINE_BREAK.split(text)
    if lines and lines[-1] == "":
        lines.pop()
    return lines


def iter_lines(text: str) -> Iterator[str]:
    """The lines of `text` as split_lines gives them, one at a time: a long source's
    lines are never all held as strings beside the text."""
    start = 0
    for line_break in LINE_BREAK.finditer(text):
        yield text[start:line_break.start()]
        start = line_break.end()
    if start < len(text):
        yield text[start:]


class LineIndex:
    """The lines of a text as split_lines gives them, each found by its index without
    holding them all as strings: 8 bytes a line (the reporter shows a few lines of a
    source that may have millions)."""

    __slots__ = ("_starts", "text")

    def __init__(self, text: str) -> None:
        self.text = text
        starts = array("q", [0])
        starts.extend(line_break.end() for line_break in LINE_BREAK.finditer(text))
        if starts[-1] == len(text):
            starts.pop()  # a final line end starts no line; an empty text has none
        self._starts = starts

    def __len__(self) -> int:
        return len(self._starts)

    def start(self, index: int) -> int:
        """Where line `index` (0-based) starts in the text."""
        return self._starts[index]

    def __getitem__(self, index: int) -> str:
        """Line `index` (0-based) without its line end."""
        start = self._starts[index]
        end = self._starts[index + 1] if index + 1 < len(self._starts) else len(self.text)
        return self.text[start:end].rstrip("\r\n")  # a line holds neither


def first_code_line_after(text: str, last: int) -> int | None:
    """The number of the first line after line `last` that holds code (anything but
    blanks before a `'`), or None: found in the text without splitting it into lines or
    parsing it, so that a source too long for a limit on lines is told so before it
    costs memory (a line of code past 65535 and the debug section, E0191)."""
    if "\r" in text:
        text = LINE_BREAK.sub("\n", text)  # one line end, for the searches below
    if text.count("\n") < last:
        return None  # `last` lines or fewer (a final line end starts no line)
    start = 0
    for _ in range(last):
        start = text.index("\n", start) + 1
    code = _CODE_LINE.search(text, start)
    return None if code is None else last + 1 + text.count("\n", start, code.start())


_CODE_LINE = re.compile(f"^[{re.escape(WHITESPACE)}]*[^{re.escape(WHITESPACE)}'\n]",
                        re.MULTILINE)
"""A line that holds code: one whose first character but blanks starts no comment."""


def decode(data: bytes, name: str = "<input>") -> Source:
    """Decode source bytes: UTF-8 (a BOM is dropped), else CP932, else refuse (compiled
    code, which holds NUL bytes as any binary file does, is named as such)."""
    if b"\x00" in data:
        from rl1.vm.ilc import MAGIC  # only for bytes that are no source: 40 ms to load

        if data.startswith(MAGIC):
            raise SourceError(name, "it is compiled code (an .ilc file), not RL/I source",
                              "run it with `rl1c run`, under a name that ends in .ilc, "
                              "or show it as text with `rl1c dis`")
        offset = data.index(b"\x00")
        raise SourceError(
            name, f"it looks like a binary file (a NUL byte at offset {offset})",
            "RL/I source is text: check that this is the .rob file you meant"
        )
    bom = data.startswith(UTF8_BOM)
    if bom:
        data = data[len(UTF8_BOM):]
    try:
        return Source(name, data.decode("utf-8"), "utf-8", bom)
    except UnicodeDecodeError as utf8_error:
        try:
            return Source(name, data.decode("cp932"), "cp932")
        except UnicodeDecodeError:
            raise SourceError(
                name, f"it is neither UTF-8 nor Shift-JIS text (invalid byte "
                f"0x{data[utf8_error.start]:02X} at offset {utf8_error.start})",
                "save it as UTF-8"
            ) from None


def read_source(path: str) -> Source:
    """Read and decode a source file, turning every OS failure into a SourceError."""
    return decode(read_bounded(path, MAX_SOURCE_BYTES, "an RL/I source file"), path)
