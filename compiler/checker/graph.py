"""The control-flow graph of a whole program: basic blocks of statements and the edges
between them, for the checker's data-flow rules (and for any later pass that wants it).

A block is entered only at its first statement. A new block starts at every labelled
line, after every `#NN`, `?V..#NN` and `(END)`, and around every line the parser could
not read (blocks.py cuts them). Blocks are numbered in source order. Edges:
- to the next block (fall-through), unless the block ends with `#NN` or `(END)`;
- `#NN` and `?V..#NN` to the block that `:NN` names (its first definition);
- `(END)`: none;
- the last block falls through to `exit`, an empty block standing for the end of the
  program (falling off the end behaves as `(END)`); a label with no code after it names
  `exit` too;
- lost-line handler edges (`Block.handlers`) to `:96`-`:99`, found by handler_edges.py.
A line with a syntax error becomes an opaque block: it may have held any statement, so
it may continue to the next block, to any labelled block or to the end, and a jump to a
label the program does not define may land on it.

Each block also carries a summary of what its statements do (effects.py), computed once
for all the data-flow rules, and the graph the device state on entry to each block,
which says which blocks some path reaches.
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

from rl1.compiler.frontend import ast

from .effects import BlockEffects

JUMPS = (ast.Goto, ast.CondJump)


def closes_block(statement: ast.Statement) -> bool:
    """Whether a block ends after `statement`: a jump or `(END)`."""
    return isinstance(statement, JUMPS) or ast.is_end(statement)


class ReadAgain(Sequence[ast.Statement]):
    """A block's statements held as where they are in the source and read from it again
    (checker/streaming.py), which say how the block ends without reading its last
    statement: the graph asks every block, and keeping every last statement's tree cost
    hundreds of bytes a block."""

    __slots__ = ()

    @property
    @abstractmethod
    def jump(self) -> ast.Goto | ast.CondJump | None:
        """What the `#NN` or `?V..#NN` that ends the block does, if one does: as
        `Block.jump`, one that may stand for the jumps of other blocks too."""

    @property
    @abstractmethod
    def ends(self) -> bool:
        """Whether the block ends with `(END)`."""


class HandlerEdge(NamedTuple):
    """A lost guidance line may jump to `:label` from the event point of the block's
    statement number `statement` (the first such in the block): right after its calls,
    before an assignment stores its value, or right after its jump."""

    label: int
    statement: int
    target: int | None  # the handler's block; None when the program does not define it


@dataclass(slots=True, eq=False)
class Block:
    """A basic block. The graph's construction fills in its edges and effects."""

    # its number; one object may stand for several blocks that never run (streaming.py),
    # numbered as the first, so the rules go by the block's place in ControlFlowGraph.blocks
    index: int
    statements: Sequence[ast.Statement]  # read from the source again when not a list
    labels: Sequence[ast.LabelDef]  # the labels naming it
    opaque: bool  # stands for a line with a syntax error
    # tuples, not lists: a program of broken lines has a block a line, so the thousands
    # of blocks without edges share the empty tuple
    successors: tuple[int, ...] = ()
    handlers: tuple[HandlerEdge, ...] = ()
    effects: BlockEffects = field(default_factory=BlockEffects.nothing)
    # what the `#NN` or `?V..#NN` that ends the block does, if one does: its kind, its
    # target, the variable it tests. The streaming check gives blocks that jump alike
    # one jump (a tree a block cost 260 bytes), so its place may be another block's:
    # where the block's own is, is its last statement. A field, not a property, so that
    # the rules gather the jumps of thousands of blocks in C (attrgetter).
    jump: ast.Goto | ast.CondJump | None = None

    def statements_at(self, index: int) -> Sequence[ast.Statement]:
        """The statements of the block at `index` in the graph: this block's own, unless
        it stands for several blocks (streaming.py's blocks that never run)."""
        return self.statements

    @property
    def ends(self) -> bool:
        """Whether the block ends with `(END)`."""
        if isinstance(self.statements, ReadAgain):
            return self.statements.ends
        return bool(self.statements) and ast.is_end(self.statements[-1])


@dataclass(slots=True, eq=False)
class ControlFlowGraph:
    blocks: list[Block]
    labels: dict[int, int]  # label number -> the block its first definition names
    labelled: list[int] = field(default_factory=list)  # the blocks labels name, in order
    opaque: list[int] = field(default_factory=list)  # the opaque blocks, in order
    # handler_edges.py's device state on entry to each block (tracing modes and motion
    # that may be in effect); 0 for a block no path reaches
    device_on_entry: list[int] = field(default_factory=list)
    entry: int = 0

    @property
    def exit(self) -> int:
        return len(self.blocks) - 1

    def reachable(self, index: int) -> bool:
        return self.device_on_entry[index] != 0

    def statements(self, index: int) -> Sequence[ast.Statement]:
        """The statements of block number `index`: the rules read them by number, as a
        block object may stand for several (streaming.py)."""
        return self.blocks[index].statements_at(index)
