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
which says which blocks some path reaches.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .. import ast
from . import device
from .effects import BlockEffects, summarize


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


def build_cfg(program: ast.Program) -> ControlFlowGraph:
    graph = _structure(program)
    graph.device_on_entry, triggers = device.trace(graph)
    for block, found in zip(graph.blocks, triggers, strict=True):
        block.handlers = [HandlerEdge(label, index, graph.labels.get(label))
                          for label, (index, _) in sorted(found.items())]
    return graph


def _structure(program: ast.Program) -> ControlFlowGraph:
    """Blocks and ordinary edges (everything but the handler edges)."""
    blocks: list[Block] = []
    labels: dict[int, int] = {}
    pending: list[ast.LabelDef] = []  # labels seen since the last statement
    statements: list[ast.Statement] | None = None  # the open block's, None when closed

    def open_block(opaque: bool = False) -> list[ast.Statement]:
        nonlocal pending
        block = Block(len(blocks), [], pending, [], [], opaque)
        for label in pending:
            if label.number is not None:
                labels.setdefault(label.number, block.index)
        pending = []
        blocks.append(block)
        return block.statements

    for line in program.lines:
        if line.label is not None:
            statements = None
            pending.append(line.label)
        if not line.ok:
            open_block(opaque=True)
            statements = None
            continue
        for statement in line.statements:
            if statements is None:
                statements = open_block()
            statements.append(statement)
            if isinstance(statement, _JUMPS) or is_end(statement):
                statements = None
    exit_index = len(blocks)
    open_block()

    opaque = [block.index for block in blocks if block.opaque]
    labelled = sorted(set(labels.values()))
    for block in blocks[:-1]:
        block.effects = summarize(block.statements)
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
