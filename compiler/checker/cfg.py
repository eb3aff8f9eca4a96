"""Building the control-flow graph (graph.py) of a program: cut it into blocks
(blocks.py), summarize each block (effects.py), add the ordinary edges, then the
lost-line handler edges (handler_edges.py).

From scratch, each block is summarized in one pass. The language server passes its
memo (incremental.py), which keeps a summary per line and the last cut, so that an edit
summarizes and cuts again only what it changed.
"""

from __future__ import annotations

from rl1.compiler.frontend import ast

from .blocks import Cut, cut, runs_of
from .effects import BlockEffects, summarize
from .graph import JUMPS, Block, ControlFlowGraph
from .handler_edges import add_handler_edges
from .incremental import LineMemo


def build_cfg(program: ast.Program, memo: LineMemo | None = None) -> ControlFlowGraph:
    """The graph of `program`; `memo` may hold what an earlier check found out about
    the lines it shares with the program."""
    if memo is None:
        cuts = cut(program.lines, runs_of).cuts
        summaries = [summarize(block.statements) or BlockEffects.nothing()
                     for block in cuts[:-1]]
    else:
        walk, summaries = memo.cut(program.lines)
        cuts = walk.cuts
    graph = _with_edges(cuts, summaries)
    add_handler_edges(graph)
    return graph


def _with_edges(cuts: list[Cut], summaries: list[BlockEffects]) -> ControlFlowGraph:
    """The blocks the cuts stand for (the exit block last), with their effects and
    ordinary edges (everything but the handler edges)."""
    blocks: list[Block] = []
    labels: dict[int, int] = {}  # label number -> the block its first definition names
    nothing = BlockEffects.nothing()  # never changed, so one does for all empty blocks
    for index, block_cut in enumerate(cuts):
        blocks.append(Block(index, block_cut.statements, block_cut.labels, block_cut.opaque,
                            [], [], nothing))
        for label in block_cut.labels:
            if label.number is not None:
                labels.setdefault(label.number, index)
    exit_index = len(blocks) - 1
    opaque = [block.index for block in blocks if block.opaque]
    labelled = sorted(set(labels.values()))
    for block, summary in zip(blocks[:-1], summaries, strict=True):
        block.effects = summary
        following = block.index + 1
        last = block.statements[-1] if block.statements else None
        if block.opaque:
            block.successors = list(dict.fromkeys([following, *labelled, exit_index]))
        elif isinstance(last, JUMPS):
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
