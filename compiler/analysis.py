"""The front end in one call: source text to AST and sorted diagnostics (those the
program's comments allow left out), or to the diagnostics alone (`diagnose`); `fix`
makes the checker's fixes."""

from __future__ import annotations

import itertools
from array import array
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import NamedTuple, overload

from .checker import apply_suppressions, check, check_text
from .checker.compact import CompactDiagnostics
from .frontend.ast import Line, Program, Span
from .frontend.diagnostics import Diagnostic, Edit, Fix, sort_key
from .frontend.edits import apply_edits, compatible
from .frontend.parser import parse_program


class Analysis(NamedTuple):
    program: Program
    diagnostics: list[Diagnostic]

    @property
    def has_errors(self) -> bool:
        return any(diagnostic.is_error for diagnostic in self.diagnostics)


def analyze(text: str) -> Analysis:
    program, diagnostics = parse_program(text)
    diagnostics.extend(check(program))
    diagnostics = apply_suppressions(program, diagnostics)
    diagnostics.sort(key=sort_key)
    return Analysis(program, diagnostics)


def diagnose(text: str) -> list[Diagnostic]:
    """`analyze(text).diagnostics`, without holding the tree (checker/streaming.py)."""
    return list(check_text(text))


def diagnose_compactly(text: str, each_line: Callable[[Line], object] | None = None
                       ) -> CompactDiagnostics:
    """`diagnose(text)`, holding those of single lines as a few bytes each until they are
    read (checker/compact.py): for `rl1c check`, whose memory is then the text's. Each
    line is handed to `each_line` as it is parsed until a line has an error (the
    compile lowers them so)."""
    return check_text(text, each_line)


MAX_FIX_ROUNDS = 10
"""Rounds of fixing before `fix` gives up: one fix can bring out another (an added
`(END)` that the vehicle reaches still moving), and fixes at one place wait a round."""


class Fixed(NamedTuple):
    """The text with the fixes made, how many were made, its diagnostics (held compactly,
    as `diagnose_compactly` gives them: neither a tree nor the diagnostics are held), and
    how many of the diagnostics `keep` accepts are left with a fix (without `unsafe`: an
    unsafe one; with it: one that would be made over an unsafe fix's result, in another
    run)."""

    text: str
    fixes: int
    diagnostics: CompactDiagnostics
    left: int


def fix(text: str, keep: Callable[[Diagnostic], bool] = lambda _: True, *,
        unsafe: bool = False) -> Fixed:
    """`text` with the fixes of the diagnostics `keep` accepts made, round after round,
    until none is left (or MAX_FIX_ROUNDS): the safe ones, and with `unsafe` the unsafe
    ones of the text as given. A fix is never made over the result of another in one
    run unless both are safe: the fixes of the first round are made on what the user
    wrote, a later round's only when they and every fix before them are safe. So an
    unsafe fix is judged on what was written (the E0201 fix writes `:05`, and W0205's
    removal of a label nobody jumps to must not be made on it), and an unsafe fix's
    consequences wait for another run. `rl1c check --fix` and the language server's
    "fix all" both make their fixes through this function."""
    diagnostics = diagnose_compactly(text)
    made = 0
    for done in range(MAX_FIX_ROUNDS):
        edits = _HeldEdits()
        fixes = 0
        safe = True
        for one in compatible(_fixes(diagnostics, keep, unsafe and done == 0)):
            edits.extend(one.edits)
            fixes += 1
            safe = safe and one.safe
        if not fixes:
            break
        text = apply_edits(text, edits)
        made += fixes
        del edits  # made: the next round's diagnostics take its place
        diagnostics = diagnose_compactly(text)
        if not safe:
            break
    left = sum(1 for d in diagnostics if keep(d) and d.fixes)
    return Fixed(text, made, diagnostics, left)


def _fixes(diagnostics: Iterable[Diagnostic], keep: Callable[[Diagnostic], bool], unsafe: bool
           ) -> Iterator[Fix]:
    """The first fix that may be made of each diagnostic `keep` accepts."""
    for diagnostic in diagnostics:
        if keep(diagnostic):
            yield from itertools.islice((one for one in diagnostic.fixes
                                         if one.safe or unsafe), 1)


class _HeldEdits(Sequence[Edit]):
    """The edits of the fixes a round of `fix` makes, in order, each held as the four
    numbers of its span and its text (one object for equal texts), and built again
    when read: a source with a fix on each line held 290 bytes of objects a fix (its
    Fix, Edit, Span and row) until all were made, 36 bytes a source byte on lines of 8."""

    __slots__ = ("_places", "_text_index", "_texts", "_which")

    def __init__(self) -> None:
        self._places = array("I")  # line, column, end line and end column of each edit
        self._which = array("I")  # the index of each edit's text in _texts
        self._texts: list[str] = []
        self._text_index: dict[str, int] = {}

    def extend(self, edits: Iterable[Edit]) -> None:
        for edit in edits:
            span = edit.span
            self._places.extend((span.line, span.column, span.end_line, span.end_column))
            which = self._text_index.get(edit.text)
            if which is None:
                which = self._text_index[edit.text] = len(self._texts)
                self._texts.append(edit.text)
            self._which.append(which)

    def __len__(self) -> int:
        return len(self._which)

    @overload
    def __getitem__(self, index: int) -> Edit: ...

    @overload
    def __getitem__(self, index: slice) -> Sequence[Edit]: ...

    def __getitem__(self, index: int | slice) -> Edit | Sequence[Edit]:
        if isinstance(index, slice):
            return [self[position] for position in range(len(self))[index]]
        position = range(len(self))[index]  # IndexError as a list gives it
        line, column, end_line, end_column = self._places[4 * position:4 * position + 4]
        return Edit(Span(line, column, end_line, end_column),
                    self._texts[self._which[position]])
