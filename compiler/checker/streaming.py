"""The whole check of a source text without its syntax tree: what `rl1c check` runs, so
that its memory is the text's and the graph's, not the tree's (issue 23, item 10;
bench/memory.py).

The lines are parsed one at a time, once: each line's syntax errors and per-line rules
are taken then, and the line's statements are cut into blocks and summarized
(effects.line_segments) as the language server's memo does. A block keeps where its
statements are, not the statements: the few rules that read them (the spans of a
block's first statement, the reads of reserved variables that may be unset, the
targets written in a busy loop) have its lines parsed again as they read
(`SourceStatements`). The diagnostics are the same as those of the tree's check
(`analysis.analyze`, which the compiler needs for its tree), and a property test holds
the two equal. The diagnostics of single lines are held as their line and kind, and
built again when read (compact.py).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import overload

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.collector import collector_paused
from rl1.compiler.frontend.diagnostics import Diagnostic, sort_by_place
from rl1.compiler.frontend.parser import parse_line
from rl1.compiler.frontend.source import LineIndex, iter_lines

from .blocks import Cut
from .cfg import graph_of
from .compact import CompactDiagnostics, LineDiagnostics, parsed_line
from .effects import BlockEffects, Combining, Segment, line_segments
from .rules import check_graph
from .suppression import MARK, Suppressions


class SourceStatements(Sequence[ast.Statement]):
    """The statements of one block, found by parsing its lines again when they are read:
    from statement `start` of line `first` (0-based indices) to the block's last,
    `last`, which is kept (every block's end is read: its jump, its `(END)`)."""

    __slots__ = ("_first", "_length", "_lines", "_start", "last")

    def __init__(self, lines: LineIndex, first: int, start: int, length: int,
                 last: ast.Statement) -> None:
        self._lines = lines
        self._first = first
        self._start = start
        self._length = length
        self.last = last

    def __len__(self) -> int:
        return self._length

    @overload
    def __getitem__(self, index: int) -> ast.Statement: ...

    @overload
    def __getitem__(self, index: slice) -> Sequence[ast.Statement]: ...

    def __getitem__(self, index: int | slice) -> ast.Statement | Sequence[ast.Statement]:
        if isinstance(index, slice):
            return tuple(self[position] for position in range(self._length)[index])
        position = range(self._length)[index]  # IndexError as a list gives it
        if position == self._length - 1:
            return self.last
        for found, statement in enumerate(self):
            if found == position:
                return statement
        raise AssertionError("a block holds fewer statements than it counted")

    def __iter__(self) -> Iterator[ast.Statement]:
        left = self._length
        number = self._first
        start = self._start
        while left:
            statements = parse_line(self._lines[number], number + 1)[0].statements
            taken = statements[start:start + left]
            yield from taken
            left -= len(taken)
            number += 1
            start = 0


class _OpenBlock:
    """The block being cut: where its statements start, how many, the effects of its
    runs combined as they come, the last statement seen."""

    __slots__ = ("cut", "effects", "first", "last", "length", "start")

    def __init__(self, cut: Cut, first: int, start: int) -> None:
        self.cut = cut
        self.first = first
        self.start = start
        self.length = 0
        self.effects = Combining()
        self.last: ast.Statement | None = None


def check_text(text: str) -> CompactDiagnostics:
    """Every diagnostic of `text`, in sort_key's order, those its comments allow left
    out: what `check` and `apply_suppressions` give on `parse_program`'s tree."""
    held = LineDiagnostics()  # those of single lines
    others: list[Diagnostic] = []
    directives: list[ast.Line] = []  # the lines whose comments may be directives
    lines = LineIndex(text)
    cuts: list[Cut] = []
    summaries: list[BlockEffects] = []
    nothing = BlockEffects.nothing()
    pending: list[ast.LabelDef] = []  # labels seen since the last statement
    block: _OpenBlock | None = None
    last_span = ast.Span(1, 1, 1, 1)

    def close() -> None:
        nonlocal block
        if block is not None:
            assert block.last is not None  # a block opens with its first run
            block.cut.statements = SourceStatements(lines, block.first, block.start,
                                                    block.length, block.last)
            summaries.append(nothing if block.effects.empty else block.effects.result())
            block = None

    with collector_paused():
        for index, line_text in enumerate(iter_lines(text)):
            line, found = parsed_line(line_text, index + 1)
            last_span = line.span
            for diagnostic in found:
                if diagnostic.span.line == index + 1:
                    held.add(index + 1, lines.start(index), diagnostic)
                else:  # none is; built again, it would be looked for on its own line
                    others.append(diagnostic)
            if line.comment is not None and MARK in line.comment.text:
                directives.append(line)
            if line.label is not None:
                close()
                pending.append(line.label)
            if not line.ok:
                close()
                # Consecutive broken lines are one opaque block (blank lines between them
                # too): each line's block would reach the next and be reached by the same
                # jumps (every jump to a missing label goes to every opaque block), so no
                # rule tells them apart; a labelled one keeps a block of its own, which
                # the label rules read.
                if pending or not _merges_into(cuts):
                    cuts.append(Cut((), _taken(pending), True, ()))
                    summaries.append(nothing)
                continue
            segments: tuple[Segment, ...] = line_segments(line.statements)
            start = 0
            for run, summary, closes in segments:
                if block is None:
                    block = _OpenBlock(Cut((), _taken(pending), False, ()), index, start)
                    cuts.append(block.cut)
                if summary is not None:
                    block.effects.add(block.length, summary)
                block.length += len(run)
                block.last = run[-1]
                start += len(run)
                if closes:
                    close()
            del line, segments, found  # the next line's tree replaces this one's
        close()
        cuts.append(Cut((), _taken(pending), False, ()))
        graph = graph_of(cuts, summaries)
        del cuts  # the blocks hold what the rules need
        others += check_graph(graph, ast.Span(1, 1, last_span.end_line, last_span.end_column))
    suppressions = Suppressions(directives)
    if not suppressions.empty:
        held = held.kept(suppressions.reports)
        others = [d for d in others
                  if suppressions.reports(d.code, d.severity, d.span.line)]
        others += suppressions.problems()
    sort_by_place(others)
    return CompactDiagnostics(text, held, suppressions.reports, others)


def _merges_into(cuts: list[Cut]) -> bool:
    """Whether a broken line without a label joins the last block cut: an opaque block
    without labels, which no statement has followed."""
    return bool(cuts) and cuts[-1].opaque and not cuts[-1].labels


def _taken(pending: list[ast.LabelDef]) -> tuple[ast.LabelDef, ...]:
    """The labels waiting for a block, which it takes: none is left waiting."""
    labels = tuple(pending)
    pending.clear()
    return labels

