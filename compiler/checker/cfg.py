"""The control-flow graph of a whole program: basic blocks of statements and the edges
between them, for the checker's data-flow rules (and for any later pass that wants it).

A block is entered only at its first statement. A new block starts at every labelled
line, after every `#NN`, `?V..#NN` and `(END)`, and around every line the parser could
not read. Blocks are numbered in source order. Edges:
- to the next block (fall-through), unless the block ends with `#NN` or `(END)`;
- `#NN` and `?V..#NN` to the block that `:NN` names (its first definition);
- `(END)`: none;
- the last block falls through to `exit`, an empty block standing for the end of the
  program (falling off the end behaves as `(END)`); a label with no code after it names
  `exit` too;
- lost-line handler edges (`Block.handlers`) to `:96`-`:99`, found by device.py's
  data-flow over the tracing mode and the motion that may be in effect.
A line with a syntax error becomes an opaque block: it may have held any statement, so
it may continue to the next block, to any labelled block or to the end, and a jump to a
label the program does not define may land on it.

Each block also carries a summary of what its statements do (effects.py), computed once
for all the data-flow rules, and the graph the device state on entry to each block,
which says which blocks some path reaches. From scratch, a block is summarized in one
pass; the language server instead keeps a summary per line (LineMemo) and puts each
block's together from those of its lines, so that an edit summarizes only what changed.
The memo also keeps how the last check cut the program into blocks: after an edit, the
cut is walked again only from the last point before the edit where no block was open
to the first such point after it, and the blocks on either side are taken as they were.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.record import Record

from . import device
from .effects import BlockEffects, Segment, combine, line_segments, relocated, summarize

Segments = tuple[Segment, ...]
Part = tuple[int, BlockEffects]  # a run's effects, and where in its block the run starts


class HandlerEdge(Record):
    """A lost guidance line may jump to `:label` from the event point of statement
    `index` of the block (the first such in the block): right after its calls, before an
    assignment stores its value, or right after its jump."""

    __slots__ = ("label", "index", "target")
    label: int
    index: int
    target: int | None  # the handler's block; None when the program does not define it

    def __init__(self, label: int, index: int, target: int | None) -> None:
        self.label = label
        self.index = index
        self.target = target


class Block(Record):
    """A basic block. The graph's construction fills in its edges and effects."""

    __slots__ = ("index", "statements", "labels", "successors", "handlers", "opaque",
                 "effects")
    index: int
    statements: list[ast.Statement]
    labels: list[ast.LabelDef]  # the labels naming it
    successors: list[int]
    handlers: list[HandlerEdge]
    opaque: bool  # stands for a line with a syntax error
    effects: BlockEffects

    def __init__(self, index: int, statements: list[ast.Statement],
                 labels: list[ast.LabelDef], opaque: bool) -> None:
        self.index = index
        self.statements = statements
        self.labels = labels
        self.successors = []
        self.handlers = []
        self.opaque = opaque
        self.effects = BlockEffects.nothing()

    @property
    def jump(self) -> ast.Goto | ast.CondJump | None:
        """The `#NN` or `?V..#NN` that ends the block, if one does."""
        last = self.statements[-1] if self.statements else None
        return last if isinstance(last, _JUMPS) else None

    @property
    def ends(self) -> bool:
        """Whether the block ends with `(END)`."""
        return bool(self.statements) and ast.is_end(self.statements[-1])


class ControlFlowGraph(Record):
    __slots__ = ("blocks", "labels", "device_on_entry", "entry")
    blocks: list[Block]
    labels: dict[int, int]  # label number -> the block its first definition names
    # device.py's state on entry to each block (tracing modes and motion that may be in
    # effect); 0 for a block no path reaches; filled in by device.py
    device_on_entry: list[int]
    entry: int

    def __init__(self, blocks: list[Block], labels: dict[int, int]) -> None:
        self.blocks = blocks
        self.labels = labels
        self.device_on_entry = []
        self.entry = 0

    @property
    def exit(self) -> int:
        return len(self.blocks) - 1

    def reachable(self, index: int) -> bool:
        return self.device_on_entry[index] != 0


_JUMPS = (ast.Goto, ast.CondJump)


class LineMemo:
    """The segments (effects.line_segments) of the lines of one document, kept between
    checks so that an edit summarizes only the lines it changed. Lines are matched by
    identity: the language server keeps the AST of an unchanged line, and tells the memo
    when it relocates one (a move changes no segment). Each entry holds its line, so an
    id cannot be reused while it is in the memo; once most entries are of lines no longer
    in the program, a check drops them. It also keeps the last check's cut of the program
    into blocks (`last_walk`), which the next check reuses around what changed. It never
    changes a result, only how soon it comes."""

    def __init__(self) -> None:
        self._entries: dict[int, tuple[ast.Line, Segments]] = {}
        self._blocks: dict[tuple[Part, ...], BlockEffects] = {}  # the last check's
        self.last_walk: _Walk | None = None  # how the last check cut its program

    def moved(self, old: ast.Line, new: ast.Line) -> None:
        """`new` is `old` relocated (ast.relocate): it has the same segments."""
        entry = self._entries.pop(id(old), None)
        if entry is not None and entry[0] is old:
            self._entries[id(new)] = (new, relocated(entry[1], new.statements))

    def segments_of(self, lines: Sequence[ast.Line]) -> list[Segments]:
        """The segments of each line, computing those of lines not seen before."""
        entries = self._entries
        found = []
        for line in lines:
            entry = entries.get(id(line))
            if entry is None or entry[0] is not line:
                entry = entries[id(line)] = (line, line_segments(line.statements))
            found.append(entry[1])
        return found

    def forget_all_but(self, lines: tuple[ast.Line, ...]) -> None:
        """Drop the entries of lines no longer in the program, once they are most."""
        if len(self._entries) > 2 * len(lines) + 1000:
            kept = (self._entries.get(id(line)) for line in lines)
            self._entries = {id(entry[0]): entry for entry in kept
                             if entry is not None}

    def block_effects(self, parts: list[list[Part]]) -> list[BlockEffects]:
        """`effects.combine` of each block's parts, reusing the last check's for a block
        made of the same runs (summaries are compared by identity)."""
        known = self._blocks
        kept: dict[tuple[Part, ...], BlockEffects] = {}
        found = []
        for block_parts in parts:
            key = tuple(block_parts)
            effects = known.get(key)
            if effects is None:
                effects = combine(block_parts)
            kept[key] = effects
            found.append(effects)
        self._blocks = kept
        return found


def build_cfg(program: ast.Program, memo: LineMemo | None = None) -> ControlFlowGraph:
    """The graph of `program`; `memo` may hold the segments of lines seen before."""
    graph = _structure(program, memo)
    graph.device_on_entry, triggers = device.trace(graph)
    for block, found in zip(graph.blocks, triggers, strict=True):
        block.handlers = [HandlerEdge(label, index, graph.labels.get(label))
                          for label, (index, _) in sorted(found.items())]
    return graph


def _structure(program: ast.Program, memo: LineMemo | None) -> ControlFlowGraph:
    """Blocks and ordinary edges (everything but the handler edges)."""
    blocks, labels, summaries = (_blocks(program) if memo is None
                                 else _blocks_from_segments(program, memo))
    exit_index = len(blocks) - 1
    opaque = [block.index for block in blocks if block.opaque]
    labelled = sorted(set(labels.values()))
    for block, summary in zip(blocks[:-1], summaries, strict=True):
        block.effects = summary
        following = block.index + 1
        last = block.statements[-1] if block.statements else None
        if block.opaque:
            block.successors = list(dict.fromkeys([following, *labelled, exit_index]))
        elif isinstance(last, _JUMPS):
            number = last.target.number
            target = labels.get(number) if number is not None else None
            found = opaque if target is None else [target]
            if isinstance(last, ast.Goto):
                block.successors = list(found)
            else:
                block.successors = [following, *(index for index in found if index != following)]
        elif last is None or not ast.is_end(last):
            block.successors = [following]
    return ControlFlowGraph(blocks, labels)


class _Cut(Record):
    """A block as the walk over the lines cut it, before any edge is known."""

    __slots__ = ("statements", "labels", "opaque", "parts")
    statements: list[ast.Statement]
    labels: list[ast.LabelDef]
    opaque: bool
    parts: list[Part]  # its runs' effects, when cut from the memo's segments (else none)

    def __init__(self, statements: list[ast.Statement], labels: list[ast.LabelDef],
                 opaque: bool, parts: list[Part]) -> None:
        self.statements = statements
        self.labels = labels
        self.opaque = opaque
        self.parts = parts


class _Walk(Record):
    """How a check cut its program into blocks: the lines, the blocks (the exit block
    last), and the lines before which no block was open and no label waited for one,
    where a walk may start afresh, each with the number of blocks cut before it."""

    __slots__ = ("lines", "cuts", "restarts")
    lines: tuple[ast.Line, ...]
    cuts: list[_Cut]
    restarts: list[tuple[int, int]]

    def __init__(self, lines: tuple[ast.Line, ...], cuts: list[_Cut],
                 restarts: list[tuple[int, int]]) -> None:
        self.lines = lines
        self.cuts = cuts
        self.restarts = restarts


def _blocks(program: ast.Program) -> tuple[list[Block], dict[int, int], list[BlockEffects]]:
    """The blocks (the exit block last), summarized one block at a time: the fastest
    way from scratch."""
    cuts: list[_Cut] = []
    statements: list[ast.Statement] | None = None  # the open block's, None when closed
    pending: list[ast.LabelDef] = []  # labels seen since the last statement
    for line in program.lines:
        if line.label is not None:
            statements = None
            pending.append(line.label)
        if not line.ok:
            cuts.append(_Cut([], pending, True, []))
            pending = []
            statements = None
            continue
        for statement in line.statements:
            if statements is None:
                statements = []
                cuts.append(_Cut(statements, pending, False, []))
                pending = []
            statements.append(statement)
            if isinstance(statement, _JUMPS) or ast.is_end(statement):
                statements = None
    cuts.append(_Cut([], pending, False, []))
    summaries = [summarize(cut.statements) or BlockEffects.nothing() for cut in cuts[:-1]]
    return *_assembled(cuts), summaries


def _blocks_from_segments(program: ast.Program, memo: LineMemo
                          ) -> tuple[list[Block], dict[int, int], list[BlockEffects]]:
    """The blocks (the exit block last), put together from the memo's line segments: the
    fastest way after an edit. An edit inside a line changes that line alone, so the
    walk restarts at the last restart point before it and stops at the first one after
    it, taking the blocks on either side from the last check."""
    walk = _walk_again(program.lines, memo) if memo.last_walk else None
    if walk is None:
        walk = _walk_lines(program.lines, 0, [], [], memo, None)
    memo.last_walk = walk
    memo.forget_all_but(program.lines)
    return *_assembled(walk.cuts), memo.block_effects([cut.parts for cut in walk.cuts[:-1]])


def _assembled(cuts: list[_Cut]) -> tuple[list[Block], dict[int, int]]:
    """The blocks the cuts stand for, and the block each label's first definition names."""
    blocks: list[Block] = []
    labels: dict[int, int] = {}
    for index, cut in enumerate(cuts):
        blocks.append(Block(index, cut.statements, cut.labels, cut.opaque))
        for label in cut.labels:
            if label.number is not None:
                labels.setdefault(label.number, index)
    return blocks, labels


def _walk_again(lines: tuple[ast.Line, ...], memo: LineMemo) -> _Walk | None:
    """The walk over `lines`, reusing the memo's last walk around what changed."""
    last = memo.last_walk
    assert last is not None
    old = last.lines
    shortest = min(len(old), len(lines))
    same_start = 0
    while same_start < shortest and old[same_start] is lines[same_start]:
        same_start += 1
    same_end = 0
    while (same_end < shortest - same_start
           and old[len(old) - 1 - same_end] is lines[len(lines) - 1 - same_end]):
        same_end += 1
    restart = bisect.bisect_right(last.restarts, (same_start, len(last.cuts))) - 1
    if restart < 0:
        return None
    start, cuts_before = last.restarts[restart]
    return _walk_lines(lines, start, last.cuts[:cuts_before], last.restarts[:restart],
                       memo, (last, len(lines) - same_end))


def _walk_lines(lines: tuple[ast.Line, ...], start: int, cuts: list[_Cut],
                restarts: list[tuple[int, int]], memo: LineMemo,
                resume: tuple[_Walk, int] | None) -> _Walk:
    """Cut `lines` from `start` on into blocks, after `cuts`. With `resume` (the last
    walk, and where the lines it also had begin), stop at the first restart point in
    that common end that the last walk shares, and take the rest from it."""
    statements: list[ast.Statement] | None = None  # the open block's, None when closed
    parts: list[Part] = []  # the open block's
    pending: list[ast.LabelDef] = []  # labels seen since the last statement
    shift = 0 if resume is None else len(lines) - len(resume[0].lines)
    # the last walk's restart points: line -> its position among them
    old_restarts = {} if resume is None else {
        line: position for position, (line, _) in enumerate(resume[0].restarts)}
    for number, (line, segments) in enumerate(
            zip(lines[start:], memo.segments_of(lines[start:]), strict=True), start=start):
        if statements is None and not pending:
            if resume is not None and number >= resume[1] and number - shift in old_restarts:
                return _resumed(lines, cuts, restarts, resume[0],
                                old_restarts[number - shift])
            restarts.append((number, len(cuts)))
        if line.label is not None:
            statements = None
            pending.append(line.label)
        if not line.ok:
            cuts.append(_Cut([], pending, True, []))
            pending = []
            statements = None
            continue
        for run, summary, closes in segments:
            if statements is None:
                statements, parts = [], []
                cuts.append(_Cut(statements, pending, False, parts))
                pending = []
            if summary is not None:
                parts.append((len(statements), summary))
            statements += run
            if closes:
                statements = None
    cuts.append(_Cut([], pending, False, []))
    return _Walk(lines, cuts, restarts)


def _resumed(lines: tuple[ast.Line, ...], cuts: list[_Cut], restarts: list[tuple[int, int]],
             last: _Walk, position: int) -> _Walk:
    """The walk so far, completed with the last walk's blocks from its restart point
    `last.restarts[position]` on (at a line both walks share, at the same distance from
    the end)."""
    shift = len(lines) - len(last.lines)
    old_cuts_before = last.restarts[position][1]
    added = len(cuts) - old_cuts_before
    cuts += last.cuts[old_cuts_before:]
    restarts += [(line + shift, count + added) for line, count in last.restarts[position:]]
    return _Walk(lines, cuts, restarts)
