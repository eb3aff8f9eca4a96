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
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .. import ast
from . import device
from .effects import BlockEffects, Segment, combine, line_segments, relocated, summarize

Segments = tuple[Segment, ...]
Part = tuple[int, BlockEffects]  # a run's effects, and where in its block the run starts


@dataclass(slots=True)
class HandlerEdge:
    """A lost guidance line may jump to `:label` from the event point of statement
    `index` of the block (the first such in the block): right after its calls, before an
    assignment stores its value, or right after its jump."""

    label: int
    index: int
    target: int | None  # the handler's block; None when the program does not define it


@dataclass(slots=True)
class Block:
    index: int
    statements: list[ast.Statement] = field(default_factory=list)
    labels: list[ast.LabelDef] = field(default_factory=list)  # the labels naming it
    successors: list[int] = field(default_factory=list)
    handlers: list[HandlerEdge] = field(default_factory=list)
    opaque: bool = False  # stands for a line with a syntax error
    effects: BlockEffects = field(default_factory=BlockEffects.nothing)

    @property
    def jump(self) -> ast.Goto | ast.CondJump | None:
        """The `#NN` or `?V..#NN` that ends the block, if one does."""
        last = self.statements[-1] if self.statements else None
        return last if isinstance(last, _JUMPS) else None

    @property
    def ends(self) -> bool:
        """Whether the block ends with `(END)`."""
        return bool(self.statements) and is_end(self.statements[-1])


@dataclass(slots=True)
class ControlFlowGraph:
    blocks: list[Block]
    labels: dict[int, int]  # label number -> the block its first definition names
    # device.py's state on entry to each block (tracing modes and motion that may be in
    # effect); 0 for a block no path reaches
    device_on_entry: list[int] = field(default_factory=list)
    entry: int = 0

    @property
    def exit(self) -> int:
        return len(self.blocks) - 1

    def reachable(self, index: int) -> bool:
        return self.device_on_entry[index] != 0


_JUMPS = (ast.Goto, ast.CondJump)


def is_end(statement: ast.Statement) -> bool:
    return isinstance(statement, ast.CallStmt) and statement.call.mnemonic.upper() == "END"


class LineMemo:
    """The segments (effects.line_segments) of the lines of one document, kept between
    checks so that an edit summarizes only the lines it changed. Lines are matched by
    identity: the language server keeps the AST of an unchanged line, and tells the memo
    when it relocates one (a move changes no segment). Each entry holds its line, so an
    id cannot be reused while it is in the memo; once most entries are of lines no longer
    in the program, a check drops them. It never changes a result, only how soon it
    comes."""

    def __init__(self) -> None:
        self._entries: dict[int, tuple[ast.Line, Segments]] = {}
        self._blocks: dict[tuple[Part, ...], BlockEffects] = {}  # the last check's

    def moved(self, old: ast.Line, new: ast.Line) -> None:
        """`new` is `old` relocated (ast.relocate): it has the same segments."""
        entry = self._entries.pop(id(old), None)
        if entry is not None and entry[0] is old:
            self._entries[id(new)] = (new, relocated(entry[1], new.statements))

    def segments_of(self, lines: tuple[ast.Line, ...]) -> list[tuple[ast.Line, Segments]]:
        """Each line with its segments, computing those of lines not seen before."""
        entries = self._entries
        found = []
        for line in lines:
            entry = entries.get(id(line))
            if entry is None or entry[0] is not line:
                entry = entries[id(line)] = (line, line_segments(line.statements))
            found.append(entry)
        if len(entries) > 2 * len(lines) + 1000:  # forget the lines edits replaced
            self._entries = {id(entry[0]): entry for entry in found}
        return found

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
        elif last is None or not is_end(last):
            block.successors = [following]
    return ControlFlowGraph(blocks, labels)


class _Blocks:
    """The blocks being cut from a program, in source order, and the labels naming them."""

    def __init__(self) -> None:
        self.blocks: list[Block] = []
        self.labels: dict[int, int] = {}  # label number -> its first definition's block
        self.pending: list[ast.LabelDef] = []  # labels seen since the last statement

    def open(self, opaque: bool = False) -> Block:
        block = Block(len(self.blocks), [], self.pending, [], [], opaque)
        for label in self.pending:
            if label.number is not None:
                self.labels.setdefault(label.number, block.index)
        self.pending = []
        self.blocks.append(block)
        return block


def _blocks(program: ast.Program) -> tuple[list[Block], dict[int, int], list[BlockEffects]]:
    """The blocks (the exit block last), summarized one block at a time: the fastest
    way from scratch."""
    cut = _Blocks()
    statements: list[ast.Statement] | None = None  # the open block's, None when closed
    for line in program.lines:
        if line.label is not None:
            statements = None
            cut.pending.append(line.label)
        if not line.ok:
            cut.open(opaque=True)
            statements = None
            continue
        for statement in line.statements:
            if statements is None:
                statements = cut.open().statements
            statements.append(statement)
            if isinstance(statement, _JUMPS) or is_end(statement):
                statements = None
    cut.open()
    summaries = [summarize(block.statements) or BlockEffects.nothing()
                 for block in cut.blocks[:-1]]
    return cut.blocks, cut.labels, summaries


def _blocks_from_segments(program: ast.Program, memo: LineMemo
                          ) -> tuple[list[Block], dict[int, int], list[BlockEffects]]:
    """The blocks (the exit block last), put together from the memo's line segments:
    the fastest way after an edit, which changes few of them."""
    cut = _Blocks()
    parts: list[list[Part]] = []  # per block but the exit: its runs' effects
    statements: list[ast.Statement] | None = None  # the open block's, None when closed
    effects: list[Part] = []  # the open block's parts
    for line, segments in memo.segments_of(program.lines):
        if line.label is not None:
            statements = None
            cut.pending.append(line.label)
        if not line.ok:
            cut.open(opaque=True)
            parts.append([])
            statements = None
            continue
        for run, summary, closes in segments:
            if statements is None:
                statements = cut.open().statements
                effects = []
                parts.append(effects)
            if summary is not None:
                effects.append((len(statements), summary))
            statements += run
            if closes:
                statements = None
    cut.open()
    return cut.blocks, cut.labels, memo.block_effects(parts)
