"""The whole check of a source text without its syntax tree: what `rl1c check` runs, so
that its memory is the text's and the graph's, not the tree's (issue 23, item 10;
bench/memory.py).

The lines are parsed one at a time, once: each line's syntax errors and per-line rules
are taken then, and the line's statements are cut into blocks and summarized
(effects.line_segments) as the language server's memo does. A block (`SourceBlock`)
keeps where its statements are, as numbers in arrays for all blocks (`BlockPlaces`),
not the statements: the few rules that read them (the spans of a block's first
statement and of its jump, the reads of reserved variables that may be unset, the
targets written in a busy loop) have its lines parsed again as they read
(`SourceStatements`). The diagnostics are the same as those of the tree's check
(`analysis.analyze`, which the compiler needs for its tree), and a property test holds
the two equal. The diagnostics of single lines are held as their line and kind, and
built again when read (compact.py).
"""

from __future__ import annotations

import functools
import itertools
from array import array
from collections.abc import Callable, Hashable, Iterator, Sequence
from typing import Generic, TypeVar, overload

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.collector import collector_paused
from rl1.compiler.frontend.diagnostics import Diagnostic, sort_by_place
from rl1.compiler.frontend.parser import parse_line
from rl1.compiler.frontend.source import LineIndex, iter_lines

from .cfg import graph_of
from .compact import (
    UNDEFINED_TARGET,
    UNSET_READ,
    CompactDiagnostics,
    Kind,
    LineDiagnostics,
    Rebuild,
    parsed_line,
)
from .effects import BlockEffects, Combining, Segment, line_segments
from .graph import Block, ReadAgain
from .labels import undefined_targets
from .reserved import unset_reads
from .rules import check_graph
from .suppression import MARK, Suppressions

Value = TypeVar("Value")


class BlockPlaces:
    """Where the statements of each block cut are in the source, as numbers in arrays
    indexed by the block's number: from statement `start` of line `first` to the block's
    last, statement `last_start` of line `last_line` (0-based indices), `length` in all,
    and the column of the target of the jump that ends it (0: none), which E0203 reports
    without reading the line again. 24 bytes a block, where an object of its place with
    a line's number took 124."""

    __slots__ = ("first", "last_line", "last_start", "length", "lines", "start", "target")

    def __init__(self, lines: LineIndex) -> None:
        self.lines = lines
        self.first = array("I")
        self.start = array("I")
        self.length = array("I")
        self.last_line = array("I")
        self.last_start = array("I")
        self.target = array("I")

    def add(self, block: int, first: int, start: int, length: int, last_line: int,
            last_start: int, target: int) -> None:
        """Hold the place of block number `block`, past those held (the blocks between,
        which hold no statements, get zeros)."""
        columns = (self.first, self.start, self.length, self.last_line, self.last_start,
                   self.target)
        missing = block - len(self.first)
        for column, value in zip(columns, (first, start, length, last_line, last_start,
                                           target), strict=True):
            if missing:
                column.extend(itertools.repeat(0, missing))
            column.append(value)


class SourceStatements(ReadAgain):
    """The statements of block number `index`, found by parsing its lines again, where
    `places` says they are, when they are read. Of the last statement only what the
    graph asks of every block is kept (`ending`): what its jump does (shared with other
    blocks, as `Block.jump`), or True for `(END)`, or False. Its tree cost 330 bytes a
    block."""

    __slots__ = ("_ending", "_index", "_places")

    def __init__(self, places: BlockPlaces, index: int,
                 ending: ast.Goto | ast.CondJump | bool) -> None:
        self._places = places
        self._index = index
        self._ending = ending

    @property
    def jump(self) -> ast.Goto | ast.CondJump | None:
        return None if isinstance(self._ending, bool) else self._ending

    @property
    def ends(self) -> bool:
        return self._ending is True

    def __len__(self) -> int:
        return self._places.length[self._index]

    @overload
    def __getitem__(self, index: int) -> ast.Statement: ...

    @overload
    def __getitem__(self, index: slice) -> Sequence[ast.Statement]: ...

    def __getitem__(self, index: int | slice) -> ast.Statement | Sequence[ast.Statement]:
        if isinstance(index, slice):
            return tuple(self[position] for position in range(len(self))[index])
        position = range(len(self))[index]  # IndexError as a list gives it
        if position == len(self) - 1:
            places = self._places
            number = places.last_line[self._index]
            line = parse_line(places.lines[number], number + 1)[0]
            return line.statements[places.last_start[self._index]]
        for found, statement in enumerate(self):
            if found == position:
                return statement
        raise AssertionError("a block holds fewer statements than it counted")

    def __iter__(self) -> Iterator[ast.Statement]:
        places = self._places
        left = places.length[self._index]
        number = places.first[self._index]
        start = places.start[self._index]
        while left:
            statements = parse_line(places.lines[number], number + 1)[0].statements
            taken = statements[start:start + left]
            yield from taken
            left -= len(taken)
            number += 1
            start = 0


class SourceBlock(Block):
    """A block of the streaming check: a graph `Block` whose statements are read from the
    source again (`SourceStatements`, made at each reading of `statements`) where
    `places` says they are, and `ending` says how the last one ends the block (as
    SourceStatements takes it). No object of statements is held: 56 bytes a block.

    One SourceBlock stands for all the blocks that never run and are alike but for their
    place (`_never_runs`): a block cost 140 bytes, and a program of `#1` lines is
    such a block every 3 bytes. Its `index` and `statements` are the first's; the
    graph's rules read each block's by its number (`statements_at`)."""

    __slots__ = ("ending", "places")

    def __init__(self, index: int, labels: Sequence[ast.LabelDef], places: BlockPlaces,
                 effects: BlockEffects) -> None:
        self.places = places
        self.ending: ast.Goto | ast.CondJump | bool = False  # until the block is closed
        super().__init__(index, (), labels, False, (), (), effects)

    @property  # over a field of Block's, which the constructor alone sets
    def statements(self) -> Sequence[ast.Statement]:
        return SourceStatements(self.places, self.index, self.ending)

    @statements.setter
    def statements(self, given: Sequence[ast.Statement]) -> None:
        """Block's constructor gives none: the places say where they are."""
        assert not given

    def statements_at(self, index: int) -> Sequence[ast.Statement]:
        return SourceStatements(self.places, index, self.ending)


class _OpenBlock:
    """The block being cut, its graph block made: where its statements start, how many,
    the effects of its runs combined as they come, the last statement seen and where."""

    __slots__ = ("block", "effects", "first", "last", "last_line", "last_start", "length",
                 "start")

    def __init__(self, block: SourceBlock, first: int, start: int) -> None:
        self.block = block
        self.first = first
        self.start = start
        self.length = 0
        self.effects = Combining()
        self.last: ast.Statement | None = None
        self.last_line = self.last_start = 0


class _Shared(Generic[Value]):
    """One object for equal values that are shared and never changed (effects, jumps),
    known by `key`: 290 bytes a block of `(END)` alone, 260 a block that jumps. The
    first LIMIT different ones are remembered, so that a program of unlike blocks holds
    no more than before."""

    LIMIT = 4096
    __slots__ = ("_key", "_known")

    def __init__(self, key: Callable[[Value], Hashable]) -> None:
        self._key = key
        self._known: dict[Hashable, Value] = {}

    def __call__(self, value: Value) -> Value:
        key = self._key(value)
        known = self._known.get(key)
        if known is not None:
            return known
        if len(self._known) < self.LIMIT:
            self._known[key] = value
        return value


def _effects_key(effects: BlockEffects) -> Hashable:
    return (tuple(effects.operations), effects.first_event, effects.reads,
            tuple(effects.writes), effects.observes, effects.calls_unknown)


def _jump_key(jump: ast.Goto | ast.CondJump) -> Hashable:
    """What the rules read of a block's jump (graph.Block.jump): all but its place."""
    if isinstance(jump, ast.Goto):
        return jump.target.text, jump.target.number
    return jump.target.text, jump.target.number, jump.var.name, jump.relation


def check_text(text: str, each_line: Callable[[ast.Line], object] | None = None
               ) -> CompactDiagnostics:
    """Every diagnostic of `text`, in sort_key's order, those its comments allow left
    out: what `check` and `apply_suppressions` give on `parse_program`'s tree.

    `each_line` is handed each line as it is parsed, in order, until a line has an
    error (no comment allows one away, so the program has errors then): the compile
    lowers the lines so, parsing each once (driver.py)."""
    held = LineDiagnostics()  # those of single lines
    others: list[Diagnostic] = []
    directives: list[ast.Line] = []  # the lines whose comments may be directives
    lines = LineIndex(text)
    places = BlockPlaces(lines)
    blocks: list[Block] = []  # the graph's, without edges until all are cut
    summaries: list[BlockEffects] = []
    nothing = BlockEffects.nothing()
    shared = _Shared(_effects_key)
    shared_jump: _Shared[ast.Goto | ast.CondJump] = _Shared(_jump_key)
    shared_dead: _Shared[tuple[SourceBlock, BlockEffects]] = _Shared(_dead_key)
    pending: list[ast.LabelDef] = []  # labels seen since the last statement
    cutting: _OpenBlock | None = None
    last_span = ast.Span(1, 1, 1, 1)

    def close() -> None:
        nonlocal cutting
        if cutting is not None:
            last = cutting.last
            assert last is not None  # a block opens with its first run
            block = cutting.block
            if isinstance(last, ast.Goto | ast.CondJump):
                target, block.ending = last.target.span.column, shared_jump(last)
            else:
                target, block.ending = 0, ast.is_end(last)
            places.add(block.index, cutting.first, cutting.start, cutting.length,
                       cutting.last_line, cutting.last_start, target)
            effects = cutting.effects
            summary = nothing if effects.empty else shared(effects.result())
            summaries.append(summary)
            if _never_runs(block, blocks):
                blocks[-1] = shared_dead((block, summary))[0]
            cutting = None

    with collector_paused():
        for index, line_text in enumerate(iter_lines(text)):
            line, found = parsed_line(line_text, index + 1)
            last_span = line.span
            for diagnostic in found:
                if diagnostic.span.line == index + 1:
                    held.add(index + 1, lines.start(index),
                             (diagnostic.code, diagnostic.severity))
                else:  # none is; built again, it would be looked for on its own line
                    others.append(diagnostic)
            if each_line is not None:
                if any(diagnostic.is_error for diagnostic in found):
                    each_line = None
                else:
                    each_line(line)
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
                if pending or not _merges_into(blocks):
                    blocks.append(Block(len(blocks), (), _taken(pending), True, (), (), nothing))
                    summaries.append(nothing)
                continue
            segments: tuple[Segment, ...] = line_segments(line.statements)
            start = 0
            for run, summary, closes in segments:
                if cutting is None:
                    made = SourceBlock(len(blocks), _taken(pending), places, nothing)
                    cutting = _OpenBlock(made, index, start)
                    blocks.append(cutting.block)
                if summary is not None:
                    cutting.effects.add(cutting.length, summary)
                cutting.length += len(run)
                start += len(run)
                cutting.last, cutting.last_line, cutting.last_start = run[-1], index, start - 1
                if closes:
                    close()
            del line, segments, found  # the next line's tree replaces this one's
        close()
        blocks.append(Block(len(blocks), (), _taken(pending), False, (), (), nothing))
        graph = graph_of(blocks, summaries)
        summaries.clear()  # the blocks hold their effects
        # the program-wide rules' that may be one a line, each in the order of its lines
        unset = LineDiagnostics()  # W0401's reads
        undefined = LineDiagnostics()  # E0203's targets
        defined_labels = ""  # what E0203's help says of the labels defined

        def unset_read(var: ast.Var) -> None:
            number = var.span.line
            unset.add(number, lines.start(number - 1), UNSET_READ, var.span.column)

        def undefined_target(index: int, defined: str) -> None:
            nonlocal defined_labels
            defined_labels = defined
            line = places.last_line[index]
            undefined.add(line + 1, lines.start(line), UNDEFINED_TARGET, places.target[index])

        others += check_graph(graph, ast.Span(1, 1, last_span.end_line, last_span.end_column),
                              unset_read, undefined_target)
        # the graph's blocks, up to 60 bytes each: let go before the merges copy what is held
        blocks.clear()
        del graph
        for program_wide in (unset, undefined):
            if program_wide.numbers:  # a copy of the lines' own, which may be one a line
                held = held.merged(program_wide)
    suppressions = Suppressions(directives)
    if not suppressions.empty:
        held = held.kept(suppressions.reports)
        others = [d for d in others
                  if suppressions.reports(d.code, d.severity, d.span.line)]
        others += suppressions.problems()
    sort_by_place(others)
    rebuilt: dict[Kind, Rebuild] = {
        UNSET_READ: unset_reads,
        UNDEFINED_TARGET: functools.partial(undefined_targets, defined=defined_labels)}
    return CompactDiagnostics(text, held, suppressions.reports, others, rebuilt=rebuilt)


def _never_runs(block: SourceBlock, blocks: list[Block]) -> bool:
    """Whether `block`, just closed and last of `blocks`, may be one object with the
    blocks alike but for their place: no path reaches it, and its edges are the same
    wherever it is. It has no label, follows a block that ends with `#NN` or `(END)`
    (so nothing falls or jumps into it: an opaque block falls into the next one, and a
    jump to no label goes to the opaque blocks), and ends so too (its successors do not
    depend on its place). A block no path reaches has no handler edges."""
    if block.labels or len(blocks) < 2 or not _ends_unconditionally(block):
        return False
    before = blocks[-2]
    return isinstance(before, SourceBlock) and _ends_unconditionally(before)


def _ends_unconditionally(block: SourceBlock) -> bool:
    return block.ending is True or isinstance(block.ending, ast.Goto)


def _dead_key(dead: tuple[SourceBlock, BlockEffects]) -> Hashable:
    """What the graph and its rules read of a block that never runs, but its place: how
    it ends and its effects."""
    block, effects = dead
    ending = block.ending
    return (ending if isinstance(ending, bool) else _jump_key(ending), _effects_key(effects))


def _merges_into(blocks: list[Block]) -> bool:
    """Whether a broken line without a label joins the last block cut: an opaque block
    without labels, which no statement has followed."""
    return bool(blocks) and blocks[-1].opaque and not blocks[-1].labels


def _taken(pending: list[ast.LabelDef]) -> tuple[ast.LabelDef, ...]:
    """The labels waiting for a block, which it takes: none is left waiting."""
    labels = tuple(pending)
    pending.clear()
    return labels

