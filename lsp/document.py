"""An open document: its lines, and a per-line cache of parse results.

RL/I is line-oriented, so an edit re-parses and re-checks (the checker's per-line rules)
only the lines whose text it changes. A cached line keeps the AST it was parsed with and
its diagnostics, all of whose spans refer to the line's `ast.Row`: when an edit above
inserts or deletes lines, the rows below are renumbered, which moves every node and
diagnostic on them at the cost of one store per line. The lines keep their identity, so
the checker's memo (incremental.py) knows them again. Lines end with LF, CRLF or a lone
CR, as LSP counts them; the last line has no ending and may be empty.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar, cast

from lsprotocol import types

from rl1.compiler.checker import LineMemo, check_line
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.collector import collector_paused
from rl1.compiler.frontend.diagnostics import Diagnostic
from rl1.compiler.frontend.parser import MAX_LINE_LENGTH, parse_line
from rl1.compiler.frontend.source import LINE_BREAK

from .positions import Columns, span_range

T = TypeVar("T")

_LINE_BREAK_KEPT = re.compile(f"({LINE_BREAK.pattern})")  # split() keeps the line ends

MAX_ANALYSED_CHARACTERS = 2_000_000
"""Beyond this a document is kept in sync but not analysed. An RL/I program of 10,000
lines is about 200,000 characters; parsing tens of megabytes would stall the server."""

MAX_ANALYSED_LINE = MAX_LINE_LENGTH
"""Nor is a document with a line longer than this (the paper's lines are under 80
characters), the longest line of code `rl1c check` reads (language.md 3.4)."""


@dataclass(slots=True)
class CachedLine:
    text: str
    row: ast.Row  # the line's number, shared by the spans of `parsed` and `problems`
    parsed: ast.Line | None = None  # None until first asked for
    problems: tuple[Diagnostic, ...] = ()  # the line's own diagnostics


def _split(text: str) -> tuple[list[str], list[str]]:
    """Line texts and their endings; the last line's ending is ""."""
    parts = _LINE_BREAK_KEPT.split(text)
    return parts[0::2], [*parts[1::2], ""]


class Document:
    def __init__(self, uri: str, text: str, version: int) -> None:
        self.uri = uri
        self.version = version
        texts, self._endings = _split(text)
        self._lines = [CachedLine(line, ast.Row(number))
                       for number, line in enumerate(texts, start=1)]
        # Lines [_stale_low, _stale_high) may be unparsed; the others are ready, so
        # preparing the program after a small edit skips them.
        self._stale_low, self._stale_high = 0, len(self._lines)
        self._size = len(text)
        self._long_lines = sum(len(line) > MAX_ANALYSED_LINE for line in texts)
        self._program: ast.Program | None = None
        self._derived: dict[Callable[[Document], object], object] = {}
        self.memo = LineMemo()  # the whole-program checker's facts about kept lines

    # Text ---------------------------------------------------------------------------

    @property
    def line_count(self) -> int:
        """Lines as LSP counts them (a final line end starts one more, empty, line)."""
        return len(self._lines)

    @property
    def too_large(self) -> bool:
        return self._size > MAX_ANALYSED_CHARACTERS or self._long_lines > 0

    def longest_line(self) -> tuple[int, int]:
        """The 1-based number and the length of the document's longest line."""
        length, index = max((len(line.text), -index) for index, line in enumerate(self._lines))
        return 1 - index, length

    @property
    def size(self) -> int:
        return self._size

    def text(self) -> str:
        return self.text_of_lines(1, len(self._lines))

    def text_of_lines(self, first: int, last: int) -> str:
        """The text of 1-based lines `first` to `last`, each with its line end."""
        pairs = zip(self._lines[first - 1 : last], self._endings[first - 1 : last], strict=True)
        return "".join(line.text + ending for line, ending in pairs)

    def line_end(self, number: int) -> str:
        """How 1-based line `number` ends: LF, CRLF, CR, or "" (the last line)."""
        return self._endings[number - 1]

    def line_text(self, number: int) -> str:
        """The text of 1-based line `number`, "" outside the document."""
        return self._lines[number - 1].text if 1 <= number <= len(self._lines) else ""

    def locate(self, position: types.Position, columns: Columns) -> tuple[int, int]:
        """A client position as a 1-based (line, code-point column), clamped into the
        document: a line past the end is the end of the document."""
        if position.line >= len(self._lines):
            last = len(self._lines)
            return last, len(self._lines[-1].text) + 1
        line = max(position.line, 0) + 1
        return line, columns.from_client(self._lines[line - 1].text, position.character) + 1

    def range_of(self, span: ast.Span, columns: Columns) -> types.Range:
        return span_range(span, self.line_text(span.line), self.line_text(span.end_line), columns)

    def end_position(self, columns: Columns) -> types.Position:
        last = self._lines[-1].text
        return types.Position(len(self._lines) - 1, columns.length(last))

    # Editing ------------------------------------------------------------------------

    def apply(self, change: types.TextDocumentContentChangeEvent, columns: Columns) -> None:
        """Apply one change; a range outside the document is clamped into it."""
        self._program = None
        self._derived.clear()
        if isinstance(change, types.TextDocumentContentChangeWholeDocument):
            texts, endings = _split(change.text)
            self._splice(0, len(self._lines), texts, endings)
            return
        start = self.locate(change.range.start, columns)
        end = self.locate(change.range.end, columns)
        start, end = min(start, end), max(start, end)
        first, last = start[0] - 1, end[0] - 1
        # A CR ending the line above and an LF starting the new text make one CRLF.
        if first > 0 and start[1] == 1 and self._endings[first - 1] == "\r":
            first -= 1
            before = self._lines[first].text + "\r"
        else:
            before = self._lines[first].text[: start[1] - 1]
        after = self._lines[last].text[end[1] - 1 :] + self._endings[last]
        texts, endings = _split(before + change.text + after)
        if self._endings[last]:
            # The window ends with a line end, so _split saw the start of the next line,
            # which the edit does not touch.
            texts.pop()
            endings.pop()
        self._splice(first, last + 1, texts, endings)

    def _splice(self, low: int, high: int, texts: list[str], endings: list[str]) -> None:
        """Replace lines [low, high) by `texts`, keeping the cache of lines whose text
        is unchanged at either end of the window."""
        old = self._lines[low:high]
        same_start = 0
        while same_start < min(len(old), len(texts)) and old[same_start].text == texts[same_start]:
            same_start += 1
        same_end = 0
        while (same_end < min(len(old), len(texts)) - same_start
               and old[-1 - same_end].text == texts[-1 - same_end]):
            same_end += 1
        middle = [CachedLine(text, ast.Row(0))  # numbered below
                  for text in texts[same_start : len(texts) - same_end]]
        kept_end = old[len(old) - same_end :] if same_end else []
        removed = sum(len(line.text) for line in old) + sum(map(len, self._endings[low:high]))
        self._long_lines += (sum(len(text) > MAX_ANALYSED_LINE for text in texts)
                             - sum(len(line.text) > MAX_ANALYSED_LINE for line in old))
        self._lines[low:high] = old[:same_start] + middle + kept_end
        self._endings[low:high] = endings
        # Number the new lines, and those below the window when it changed size.
        renumber_to = low + len(texts) if len(texts) == high - low else len(self._lines)
        for number in range(low + same_start, renumber_to):
            self._lines[number].row.number = number + 1
        # The window of unparsed lines: an earlier one moves with the lines below this
        # edit, and takes in the new lines.
        moved_by = len(texts) - (high - low)
        if self._stale_low < self._stale_high:
            if self._stale_low >= high:
                self._stale_low += moved_by
            else:
                self._stale_low = min(self._stale_low, low)
            if self._stale_high > low:
                self._stale_high = max(self._stale_high + moved_by, low + len(texts))
        if middle:
            self._stale_low = min(self._stale_low, low + same_start)
            self._stale_high = max(self._stale_high, low + same_start + len(middle))
        self._stale_high = min(self._stale_high, len(self._lines))
        self._size += sum(map(len, texts)) + sum(map(len, endings)) - removed

    # Syntax -------------------------------------------------------------------------

    def line(self, number: int) -> ast.Line:
        """The AST of 1-based line `number`, parsing it if need be."""
        cached = self._lines[number - 1]
        if cached.parsed is None:
            cached.parsed, problems = parse_line(cached.text, cached.row)
            cached.problems = (*problems, *check_line(cached.parsed))
        return cached.parsed

    def prepare(self, first: int, last: int) -> None:
        """Parse lines `first`..`last` (1-based, inclusive) now, so that a caller can
        spread the work of a large change between other tasks."""
        low, high = max(first, self._stale_low + 1), min(last, self._stale_high)
        with collector_paused():
            for number in range(low, high + 1):
                if self._lines[number - 1].parsed is None:
                    self.line(number)
        if low <= high and low == self._stale_low + 1:
            self._stale_low = high  # the stale window now starts below what was done
        if self._stale_low >= self._stale_high:
            self._stale_low, self._stale_high = len(self._lines), 0

    def unprepared(self) -> range:
        """The 1-based numbers of the lines an edit may have left unparsed (prepare()
        makes them ready); the others are ready already."""
        return range(self._stale_low + 1, min(self._stale_high, self.program_lines()) + 1)

    def problems(self) -> list[Diagnostic]:
        """The diagnostics of every line alone, in line order."""
        self.program()  # parses what needs it
        return [problem for cached in self._lines if cached.problems
                for problem in cached.problems]

    def program_lines(self) -> int:
        """The lines the compiler sees: a final empty line after a line end is not one."""
        if self._lines[-1].text == "":
            return len(self._lines) - 1
        return len(self._lines)

    def program(self) -> ast.Program:
        """The whole program, as `parser.parse_program` would build it from the text."""
        if self._program is None:
            # All lines, the final empty one too, so that the stale window closes.
            self.prepare(1, len(self._lines))
            count = self.program_lines()
            lines = cast(tuple[ast.Line, ...],  # prepare() parsed every one of them
                         tuple([cached.parsed for cached in self._lines[:count]]))
            end = lines[-1].span if lines else ast.Span(1, 1, 1, 1)
            self._program = ast.Program(ast.Span(1, 1, end.end_line, end.end_column), lines)
        return self._program

    def derived(self, build: Callable[[Document], T]) -> T:
        """`build(self)`, computed once per version: the indexes features share."""
        if build not in self._derived:
            self._derived[build] = build(self)
        return cast(T, self._derived[build])
