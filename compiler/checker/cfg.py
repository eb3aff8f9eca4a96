"""Building the control-flow graph (graph.py) of a program: cut it into blocks
(blocks.py), summarize each block (effects.py), add the ordinary edges, then the
lost-line handler edges (handler_edges.py).

From scratch, each block is summarized in one pass. The language server passes its
memo (incremental.py), which keeps a summary per line and the last cut, so that an edit
summarizes and cuts again only what it changed.
"""

from __future__ import annotations

import itertools
import operator
from collections.abc import Iterable, Sequence

from rl1.compiler.frontend import ast

from .blocks import Cut, cut, runs_of
from .effects import BlockEffects, summarize
from .graph import JUMPS, Block, ControlFlowGraph, ReadAgain
from .handler_edges import add_handler_edges
from .incremental import LineMemo

_LABELS = operator.attrgetter("labels")
_OPAQUE = operator.attrgetter("opaque")


def build_cfg(program: ast.Program, memo: LineMemo | None = None) -> ControlFlowGraph:
    """The graph of `program`; `memo` may hold what an earlier check found out about
    the lines it shares with the program."""
    if memo is None:
        cuts = cut(program.lines, runs_of).cuts
        nothing = BlockEffects.nothing()  # never changed: one for every block without effects
        summaries = [summarize(block.statements) or nothing for block in cuts[:-1]]
    else:
        walk, summaries = memo.cut(program.lines)
        cuts = walk.cuts
    previous = memo.last_graph if memo is not None else None
    graph = _with_edges(cuts, summaries, *(previous or ([], None)))
    if memo is not None:
        memo.last_graph = (cuts, graph)
    add_handler_edges(graph)
    return graph


def graph_of(blocks: list[Block], summaries: list[BlockEffects]) -> ControlFlowGraph:
    """The graph of blocks cut elsewhere as Blocks without edges (streaming.py, which
    holds no Cut besides: a block each costs), with the effects of each but the exit
    block."""
    labelled, opaque, labels = _labels_of(blocks)
    _link(blocks, range(len(blocks) - 1), summaries, labels, opaque)
    graph = ControlFlowGraph(blocks, labels, labelled, opaque)
    add_handler_edges(graph)
    return graph


def _with_edges(cuts: list[Cut], summaries: list[BlockEffects], last_cuts: list[Cut],
                previous: ControlFlowGraph | None) -> ControlFlowGraph:
    """The blocks the cuts stand for (the exit block last), with their effects and
    ordinary edges (everything but the handler edges). `previous` is the graph the same
    memo built from `last_cuts`: when the blocks keep their numbers, the labels and the
    opaque blocks, a block cut the same keeps its edges, so its Block is taken over
    (edited in place: the memo's last graph is not kept by anyone else)."""
    labelled, opaque, labels = _labels_of(cuts)
    exit_index = len(cuts) - 1
    nothing = BlockEffects.nothing()  # never changed, so one does for all empty blocks
    if (previous is None or len(last_cuts) != len(cuts) or previous.labels != labels
            or previous.opaque != opaque):
        blocks = [Block(index, block_cut.statements, block_cut.labels, block_cut.opaque,
                        (), (), nothing) for index, block_cut in enumerate(cuts)]
        changed: Iterable[int] = range(len(cuts) - 1)
    else:
        blocks = previous.blocks
        # the blocks whose cut is new, found in C: an edit changes one or two of thousands
        changed = list(itertools.compress(range(len(cuts)), map(operator.is_not, cuts, last_cuts)))
        for index in changed:
            block_cut = cuts[index]
            blocks[index] = Block(index, block_cut.statements, block_cut.labels,
                                  block_cut.opaque, (), (), nothing)
        if changed and changed[-1] == exit_index:
            changed.pop()  # the exit block has no effects nor edges
    _link(blocks, changed, summaries, labels, opaque)
    return ControlFlowGraph(blocks, labels, labelled, opaque)


def _labels_of(cuts: Sequence[Cut | Block]) -> tuple[list[int], list[int], dict[int, int]]:
    """The labelled blocks and the opaque ones, in order, and the block each label's
    first definition names."""
    # the few labelled and opaque blocks among thousands, found in C
    labelled = list(itertools.compress(range(len(cuts)), map(_LABELS, cuts)))
    opaque = list(itertools.compress(range(len(cuts)), map(_OPAQUE, cuts)))
    labels: dict[int, int] = {}  # label number -> the block its first definition names
    for index in labelled:
        for label in cuts[index].labels:
            if label.number is not None:
                labels.setdefault(label.number, index)
    return labelled, opaque, labels


def _link(blocks: list[Block], changed: Iterable[int], summaries: list[BlockEffects],
          labels: dict[int, int], opaque: list[int]) -> None:
    """Give the `changed` blocks their effects and ordinary edges."""
    exit_index = len(blocks) - 1
    named = sorted(set(labels.values()))
    # the successors of a `#NN` depend on its target alone: one tuple for each (48
    # bytes a block of a program that jumps on every line)
    gotos: dict[int | None, tuple[int, ...]] = {}
    for index in changed:
        block = blocks[index]
        summary = summaries[index]
        block.effects = summary
        following = index + 1
        jump, ends = _ending(block.statements)
        if block.opaque:
            block.successors = tuple(dict.fromkeys([following, *named, exit_index]))
        elif jump is not None:
            block.jump = jump
            number = jump.target.number
            target = labels.get(number) if number is not None else None
            found = opaque if target is None else [target]
            if isinstance(jump, ast.Goto):
                successors = gotos.get(target)
                if successors is None:
                    successors = gotos[target] = tuple(found)
                block.successors = successors
            else:
                block.successors = (following, *(other for other in found if other != following))
        elif not ends:
            block.successors = (following,)


def _ending(statements: Sequence[ast.Statement]) -> tuple[ast.Goto | ast.CondJump | None, bool]:
    """The jump that ends a block of `statements`, if one does, and whether `(END)` does."""
    if isinstance(statements, ReadAgain):
        return statements.jump, statements.ends
    last = statements[-1] if statements else None
    return (last if isinstance(last, JUMPS) else None), last is not None and ast.is_end(last)
