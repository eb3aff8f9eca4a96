"""A text's diagnostics in sort order, those of single lines held as a few bytes each and
built again from their line when read: what `rl1c check` reports (issue 23, item 10;
bench/memory.py).

A source of a syntax error a line would otherwise hold 516 bytes of objects a line (the
E0101, its span, its row, its fix, the fix's edit and span), 64 bytes a source byte on
their own; no part of them can be shared between lines, since every span rides on its
line's `ast.Row`, which the language server renumbers in place. So the diagnostics the
parser and `check_line` give on a line are kept as their line's number, where it
starts, and their kind (code and severity): 14 bytes each. Reading them parses their
line again (what a line gives is a function of its text and its number), keeps what
was kept of them, and merges them into the others, which are few and held whole (the
program-wide rules', the W0107s of suppression comments). Of the program-wide rules',
W0401 and E0203 may be one a line; they are held by line too, with the column of the
read or the jump's target, and built again from their line (`Rebuild`:
reserved.unset_reads, labels.undefined_targets). Reading costs a second parse
of each line held: `rl1c check` on a source of a syntax error a line takes about 1.4
times the processor time it took when they were held whole, and a twelfth of the memory.
"""

from __future__ import annotations

import itertools
from array import array
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import overload

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity, sort_key
from rl1.compiler.frontend.parser import parse_line
from rl1.compiler.frontend.source import LINE_BREAK

from .lines import check_line
from .reserved import unset_reads

Kind = tuple[str, Severity]
"""What a held diagnostic is known by until it is built: its code and severity."""

Keeps = Callable[[str, Severity, int], bool]
"""Whether a diagnostic of a code and severity on a line (1-based) is kept."""


def parsed_line(text: str, number: int) -> tuple[ast.Line, list[Diagnostic]]:
    """Line `number` (1-based), whose text is `text`, and its diagnostics alone: the
    parser's, then `check_line`'s."""
    line, found = parse_line(text, number)
    found += check_line(line)
    return line, found


UNSET_READ: Kind = ("W0401", Severity.WARNING)
"""A read of a reserved variable that may be unset (reserved.py): held by line, one a
line in a source of `A=s` lines, 250 bytes each held whole."""

UNDEFINED_TARGET: Kind = ("E0203", Severity.ERROR)
"""A jump to a label no line defines (labels.py): held by line, one a line in a source
of `#01` lines without `:01`, 400 bytes each held whole."""

Rebuild = Callable[[ast.Line, list[int]], list[Diagnostic]]
"""The diagnostics of a program-wide rule held by line, built again from their line:
those at the columns given."""


class LineDiagnostics:
    """The diagnostics of single lines while a text is checked, each held as its line's
    number, where the line starts in the text, an index into the kinds seen (4, 8 and 2
    bytes), and once a program-wide rule's is held (`Rebuild`), the column it is built
    again from, 0 for a diagnostic the line gives alone (4 bytes): a text's lines are
    found again without an index of them all."""

    __slots__ = ("_index", "columns", "kinds", "numbers", "of_kind", "starts")

    def __init__(self, kinds: list[Kind] | None = None) -> None:
        self.numbers = array("I")  # 32 bits: a source holds far fewer lines
        self.starts = array("q")
        self.of_kind = array("H")
        self.columns: array[int] | None = None  # None until a read's column is held
        self.kinds: list[Kind] = kinds or []
        self._index = {kind: index for index, kind in enumerate(self.kinds)}

    def add(self, number: int, start: int, kind: Kind, column: int = 0) -> None:
        """Hold a diagnostic of `kind` given by line `number`, which starts at `start`
        in the text (the next lines' come after); `column` is the one a program-wide
        rule's is built again from."""
        index = self._index.get(kind)
        if index is None:
            index = self._index[kind] = len(self.kinds)
            self.kinds.append(kind)
        self._append(number, start, index, column)

    def _append(self, number: int, start: int, index: int, column: int) -> None:
        if column and self.columns is None:
            self.columns = array("I", [0]) * len(self.numbers)
        if self.columns is not None:
            self.columns.append(column)
        self.numbers.append(number)
        self.starts.append(start)
        self.of_kind.append(index)

    def rebuilt_of(self, start: int, end: int) -> dict[Kind, list[int]]:
        """The columns of the program-wide rules' diagnostics held from position `start`
        to `end`, by kind."""
        found: dict[Kind, list[int]] = {}
        if self.columns is not None:
            for index, column in zip(self.of_kind[start:end], self.columns[start:end],
                                     strict=True):
                if column:
                    found.setdefault(self.kinds[index], []).append(column)
        return found

    def _entries(self) -> Iterator[tuple[int, int, int, int]]:
        columns = self.columns
        if columns is None:
            return zip(self.numbers, self.starts, self.of_kind,
                       itertools.repeat(0, len(self.numbers)), strict=True)
        return zip(self.numbers, self.starts, self.of_kind, columns, strict=True)

    def kept(self, keeps: Keeps) -> LineDiagnostics:
        """Those that `keeps` keeps."""
        kept = LineDiagnostics(self.kinds)
        for number, start, index, column in self._entries():
            code, severity = self.kinds[index]
            if keeps(code, severity, number):
                kept._append(number, start, index, column)
        return kept

    def merged(self, other: LineDiagnostics) -> LineDiagnostics:
        """These and `other`'s, in the order of their lines."""
        merged = LineDiagnostics(list(self.kinds))
        for kind in other.kinds:
            if kind not in merged._index:
                merged._index[kind] = len(merged.kinds)
                merged.kinds.append(kind)
        renumbered = [merged._index[kind] for kind in other.kinds]
        theirs = other._entries()
        their = next(theirs, None)
        for entry in self._entries():
            while their is not None and their[0] < entry[0]:
                merged._append(their[0], their[1], renumbered[their[2]], their[3])
                their = next(theirs, None)
            merged._append(*entry)
        while their is not None:
            merged._append(their[0], their[1], renumbered[their[2]], their[3])
            their = next(theirs, None)
        return merged


class CompactDiagnostics(Sequence[Diagnostic]):
    """Every diagnostic of a text in sort_key's order, as `analysis.diagnose` gives
    them: those of single lines held in `held` (those a line gives that `keeps` keeps,
    and the program-wide rules' that `rebuilt` builds again, built again when read), the
    `others` whole, in order. Reading them all parses each line of `held` once;
    `severities` says what they are without building any."""

    __slots__ = ("_as_errors", "_held", "_keeps", "_others", "_rebuilt", "_text")

    def __init__(self, text: str, held: LineDiagnostics, keeps: Keeps,
                 others: list[Diagnostic], *, as_errors: bool = False,
                 rebuilt: Mapping[Kind, Rebuild] | None = None) -> None:
        self._text = text
        self._held = held
        self._keeps = keeps
        self._others = others
        self._as_errors = as_errors
        self._rebuilt = rebuilt if rebuilt is not None else {UNSET_READ: unset_reads}

    def selected(self, reports: Callable[[str, Severity], bool], as_errors: bool
                 ) -> CompactDiagnostics:
        """Those whose code and severity (as checked) `reports` accepts, warnings made
        errors when `as_errors`: what a `Selection` reports, none of them built."""
        keeps = self._keeps

        def kept(code: str, severity: Severity, number: int) -> bool:
            return keeps(code, severity, number) and reports(code, severity)

        others = [self._made_error(d) if as_errors else d for d in self._others
                  if reports(d.code, d.severity)]
        return CompactDiagnostics(self._text, self._held.kept(kept), kept, others,
                                  as_errors=self._as_errors or as_errors,
                                  rebuilt=self._rebuilt)

    def severities(self) -> Iterator[Severity]:
        """The severity of each diagnostic, in no particular order."""
        kinds = self._held.kinds
        for index in self._held.of_kind:
            yield self._severity(kinds[index][1])
        for diagnostic in self._others:
            yield diagnostic.severity

    def __len__(self) -> int:
        return len(self._held.numbers) + len(self._others)

    def __iter__(self) -> Iterator[Diagnostic]:
        others = self._others
        other = 0  # the next of `others` to give
        numbers = self._held.numbers
        position = 0
        while position < len(numbers):
            number = numbers[position]
            end = position + 1
            while end < len(numbers) and numbers[end] == number:
                end += 1
            built = self._built(number, self._held.starts[position],
                                self._held.rebuilt_of(position, end))
            if len(built) != end - position:
                raise AssertionError(f"line {number} gave other diagnostics than it did")
            position = end
            for diagnostic in built:
                # Equal places: the line's first, as a stable sort of the line's
                # diagnostics and then the others would put them.
                while other < len(others) and sort_key(others[other]) < sort_key(diagnostic):
                    yield others[other]
                    other += 1
                yield diagnostic
        yield from others[other:]

    @overload
    def __getitem__(self, index: int) -> Diagnostic: ...

    @overload
    def __getitem__(self, index: slice) -> Sequence[Diagnostic]: ...

    def __getitem__(self, index: int | slice) -> Diagnostic | Sequence[Diagnostic]:
        if isinstance(index, slice):
            wanted = range(len(self))[index]
            return tuple(d for position, d in enumerate(self) if position in wanted)
        position = range(len(self))[index]  # IndexError as a list gives it
        for found, diagnostic in enumerate(self):
            if found == position:
                return diagnostic
        raise AssertionError("fewer diagnostics were built than were held")

    def _built(self, number: int, start: int, rebuilt: dict[Kind, list[int]]
               ) -> list[Diagnostic]:
        """The diagnostics held of line `number`, which starts at `start` in the text,
        built again, in sort_key's order; `rebuilt` has the columns of the program-wide
        rules' held, by kind."""
        end = LINE_BREAK.search(self._text, start)
        text = self._text[start:end.start() if end else len(self._text)]
        line, found = parsed_line(text, number)
        for kind, columns in rebuilt.items():
            found += self._rebuilt[kind](line, columns)
        built = [self._made_error(d) if self._as_errors else d for d in found
                 if d.span.line == number and self._keeps(d.code, d.severity, number)]
        built.sort(key=_place_in_line)
        return built

    def _severity(self, severity: Severity) -> Severity:
        if self._as_errors and severity is Severity.WARNING:
            return Severity.ERROR
        return severity

    @staticmethod
    def _made_error(diagnostic: Diagnostic) -> Diagnostic:
        if diagnostic.severity is Severity.WARNING:
            return diagnostic._replace(severity=Severity.ERROR)
        return diagnostic


def _place_in_line(diagnostic: Diagnostic) -> tuple[int, str]:
    return diagnostic.span.column, diagnostic.code
