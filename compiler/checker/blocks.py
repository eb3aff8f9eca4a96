"""The block cutter: a program's lines to the blocks of its control-flow graph (graph.py
says where a block starts and ends), before any edge is known. Used both from scratch
and by the language server's incremental check (incremental.py), which cuts again only
around what an edit changed.

A line is handed to the cutter as its segments (effects.Segment): the runs of its
statements that lie in one block, each closing its block or not, with what the run
does when the caller has summarized it. The cutter also records its restart points:
the lines before which no block was open and no label waited for one. A cut may start
afresh at any of them, and a cut that meets one it shares with the last cut, in the
lines both have, may take the rest of its blocks from that cut.
"""

from __future__ import annotations

import bisect
import operator
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from rl1.compiler.frontend import ast

from .effects import BlockEffects, Segment
from .graph import closes_block

Segments = tuple[Segment, ...]
Part = tuple[int, BlockEffects]  # a run's effects, and where in its block the run starts
SegmentsOf = Callable[[Sequence[ast.Line]], Iterable[Segments]]


@dataclass(slots=True, eq=False)
class Cut:
    """A block as the cutter cut it."""

    # a list as cut here; streaming.py's cut keeps where they are in the source instead
    statements: Sequence[ast.Statement]
    labels: Sequence[ast.LabelDef]
    opaque: bool
    parts: Sequence[Part]  # the effects of its runs that do something (summarized segments only)
    # what the whole block does, once the incremental memo has combined its parts; a cut
    # reused by the next walk keeps it
    effects: BlockEffects | None = None


@dataclass(slots=True, eq=False)
class Walk:
    """How a program was cut: its lines, the blocks (the exit block last), and the
    restart points, each as (line index, number of blocks cut before it)."""

    lines: tuple[ast.Line, ...]
    cuts: list[Cut]
    restarts: list[tuple[int, int]]


def runs_of(lines: Sequence[ast.Line]) -> Iterable[Segments]:
    """The segments of each line, not summarized: what a cut from scratch needs."""
    for line in lines:
        statements = line.statements
        segments: list[Segment] = []
        start = 0
        for index, statement in enumerate(statements):
            if closes_block(statement):
                segments.append((statements[start : index + 1], None, True))
                start = index + 1
        if start < len(statements):
            segments.append((statements[start:] if start else statements, None, False))
        yield tuple(segments)


def cut(lines: tuple[ast.Line, ...], segments_of: SegmentsOf) -> Walk:
    """Cut `lines` into blocks from scratch."""
    return _cut(lines, 0, [], [], segments_of, None)


def cut_again(lines: tuple[ast.Line, ...], last: Walk, segments_of: SegmentsOf) -> Walk:
    """Cut `lines` into blocks, reusing `last` (a cut of lines that may share a start
    and an end with them, by identity) around what changed: the cut restarts at the last
    restart point before the first changed line, and stops at the first restart point
    after the last one that `last` shares."""
    old = last.lines
    shortest = min(len(old), len(lines))
    same_start = _same_run(old, lines)
    same_end = min(_same_run(old[::-1], lines[::-1]), shortest - same_start)
    restart = bisect.bisect_right(last.restarts, (same_start, len(last.cuts))) - 1
    if restart < 0:
        return cut(lines, segments_of)
    start, cuts_before = last.restarts[restart]
    return _cut(lines, start, last.cuts[:cuts_before], last.restarts[:restart], segments_of,
                (last, len(lines) - same_end))


def _same_run(old: tuple[ast.Line, ...], new: tuple[ast.Line, ...]) -> int:
    """How many lines the two start with that are the same objects (compared in C: the
    server's documents have 10,000 lines, and an edit changes one or two)."""
    same = list(map(operator.is_, old, new))
    return same.index(False) if False in same else len(same)


def _cut(lines: tuple[ast.Line, ...], start: int, cuts: list[Cut],
         restarts: list[tuple[int, int]], segments_of: SegmentsOf,
         resume: tuple[Walk, int] | None) -> Walk:
    """Cut `lines` from `start` on into blocks, after `cuts`. With `resume` (the last
    walk, and where the lines it also had begin), stop at the first restart point in
    that common end that the last walk shares, and take the rest from it."""
    statements: list[ast.Statement] | None = None  # the open block's, None when closed
    parts: list[Part] = []  # the open block's
    pending: list[ast.LabelDef] = []  # labels seen since the last statement
    shift = 0 if resume is None else len(lines) - len(resume[0].lines)
    old_restarts = [] if resume is None else resume[0].restarts  # sorted by line
    for number, (line, segments) in enumerate(
            zip(lines[start:], segments_of(lines[start:]), strict=True), start=start):
        if statements is None and not pending:
            if resume is not None and number >= resume[1]:
                # found by bisection: a dict of them all would cost the whole program
                position = bisect.bisect_left(old_restarts, (number - shift, 0))
                if position < len(old_restarts) and old_restarts[position][0] == number - shift:
                    return _resumed(lines, cuts, restarts, resume[0], position)
            restarts.append((number, len(cuts)))
        if line.label is not None:
            statements = None
            pending.append(line.label)
        if not line.ok:
            cuts.append(Cut([], pending, True, []))
            pending = []
            statements = None
            continue
        for run, summary, closes in segments:
            if statements is None:
                statements, parts = [], []
                cuts.append(Cut(statements, pending, False, parts))
                pending = []
            if summary is not None:
                parts.append((len(statements), summary))
            statements += run
            if closes:
                statements = None
    cuts.append(Cut([], pending, False, []))
    return Walk(lines, cuts, restarts)


def _resumed(lines: tuple[ast.Line, ...], cuts: list[Cut], restarts: list[tuple[int, int]],
             last: Walk, position: int) -> Walk:
    """The walk so far, completed with the last walk's blocks from its restart point
    `last.restarts[position]` on (at a line both walks share, at the same distance from
    the end)."""
    shift = len(lines) - len(last.lines)
    old_cuts_before = last.restarts[position][1]
    added = len(cuts) - old_cuts_before
    cuts += last.cuts[old_cuts_before:]
    if shift == 0 and added == 0:
        restarts += last.restarts[position:]
    else:
        restarts += [(line + shift, count + added) for line, count in last.restarts[position:]]
    return Walk(lines, cuts, restarts)
