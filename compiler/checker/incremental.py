"""The language server's incremental memo: what the whole-program check keeps about a
document between two of its checks, so that an edit costs about what it touches.

A check from scratch summarizes each block in one pass (cfg.py). The language server
instead keeps the segments of each line (effects.line_segments: what its runs of
statements do), puts each block's summary together from those of its lines, and keeps
the last check's cut of the program into blocks, which the next check cuts again only
around what changed (blocks.cut_again). It never changes a result, only how soon it
comes.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import cast

from rl1.compiler.frontend import ast

from .blocks import Cut, Segments, Walk, cut, cut_again
from .effects import BlockEffects, combine, line_segments
from .graph import ControlFlowGraph


class LineMemo:
    """The segments of the lines of one document, and the last check's cut. Lines are
    matched by identity: the language server keeps the AST of a line whose text an edit
    did not change, wherever the line moves. Each entry holds its line, so an id cannot
    be reused while it is in the memo; once most entries are of lines no longer in the
    program, a check drops them."""

    def __init__(self) -> None:
        self._entries: dict[int, tuple[ast.Line, Segments]] = {}
        self.last_walk: Walk | None = None  # how the last check cut its program
        # the last check's cuts and graph, whose blocks cfg.py reuses for the cuts it shares
        self.last_graph: tuple[list[Cut], ControlFlowGraph] | None = None

    def cut(self, lines: tuple[ast.Line, ...]) -> tuple[Walk, list[BlockEffects]]:
        """The cut of `lines` into blocks, and the effects of each block but the exit."""
        if self.last_walk is None:
            walk = cut(lines, self.segments_of)
        else:
            walk = cut_again(lines, self.last_walk, self.segments_of)
        self.last_walk = walk
        self._forget_all_but(lines)
        return walk, _block_effects(walk.cuts[:-1])

    def segments_of(self, lines: Sequence[ast.Line]) -> Iterator[Segments]:
        """The segments of each line, computing those of lines not seen before; lazily,
        as the cutter stops as soon as it meets the last cut again."""
        entries = self._entries
        for line in lines:
            entry = entries.get(id(line))
            if entry is None or entry[0] is not line:
                entry = entries[id(line)] = (line, line_segments(line.statements))
            yield entry[1]

    def _forget_all_but(self, lines: tuple[ast.Line, ...]) -> None:
        """Drop the entries of lines no longer in the program, once they are most."""
        if len(self._entries) > 2 * len(lines) + 1000:
            kept = (self._entries.get(id(line)) for line in lines)
            self._entries = {id(entry[0]): entry for entry in kept
                             if entry is not None}


def _block_effects(cuts: list[Cut]) -> list[BlockEffects]:
    """`effects.combine` of each cut's parts, kept on the cut: a cut the walk took over
    from the last one has them already."""
    for block_cut in cuts:
        if block_cut.effects is None:
            block_cut.effects = combine(block_cut.parts)
    return [cast(BlockEffects, block_cut.effects) for block_cut in cuts]
