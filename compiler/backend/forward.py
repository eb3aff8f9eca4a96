"""The forward data flow that constant folding (constants.py) and the signs of branches
(signs.py) both run: what is known where each block starts, from what its predecessors
know where their edges leave them, until nothing changes.

A worklist of the blocks whose start changed, the first in the layout first (most
edges go forward, so a block is seldom visited before a predecessor that comes before
it), from the roots (flow.roots). A visit may decide that an edge is not taken (a
branch on a known value): code behind a way never taken learns nothing from it.

What is known where a block starts is combined as each edge into it is followed, not
gathered again from its predecessors: the flow is monotone (a visit from less knowledge
knows less where it ends, and takes every edge a visit from more took), so what an
edge leads in with only ever loses knowledge, and combining it with what was known
before is combining what the predecessors' last visits lead in with. The result is the
flow's one greatest fixed point, whatever the order of the visits.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable, Iterable
from typing import TypeVar

from . import flow, ir

State = TypeVar("State")
Visited = TypeVar("Visited")


def solve(program: ir.Program, *, entry: State, handler: State,
          combine: Callable[[State, State], State],
          visit: Callable[[ir.Block, State], Visited],
          edges: Callable[[ir.Block, Visited], Iterable[tuple[ir.BlockId, State]]]
          ) -> dict[ir.BlockId, Visited]:
    """What `visit` gives for each block some path reaches, from what is known where it
    starts: `combine` of what `entry` (the program's start) or `handler` (a handler's
    start, where an event arrives from anywhere) say and of the states the `edges` of
    the visits of its predecessors lead into it with.

    What the flow holds of each block is in lists by its place in the layout (a block a
    line of `?A<#01` held 400 bytes of the flow's dictionaries and lists, 57 bytes a
    source byte): what is known where it starts, and its last visit."""
    places = flow.Places(program)
    blocks, place_of = places.blocks, places.place
    known: list[State | None] = [None] * len(blocks)  # where each block starts
    known[place_of[program.entry]] = entry
    for block_id in program.handlers.values():
        place = place_of[block_id]
        before = known[place]
        known[place] = handler if before is None else combine(before, handler)
    visited: list[Visited | None] = [None] * len(blocks)
    work = sorted(place_of[block_id] for block_id in flow.roots(program))
    queued = bytearray(len(blocks))
    for place in work:
        queued[place] = 1
    while work:
        place = heapq.heappop(work)
        queued[place] = 0
        block, start = blocks[place], known[place]
        assert start is not None  # queued once something led into it
        visited[place] = after = visit(block, start)
        for target_id, leaving in edges(block, after):
            target = place_of[target_id]
            before = known[target]
            if before is None:
                known[target] = leaving
            else:
                if leaving is before:
                    continue
                combined = combine(before, leaving)
                if combined is before or combined == before:
                    continue
                known[target] = combined
            if not queued[target]:
                queued[target] = 1
                heapq.heappush(work, target)
    del known
    return {blocks[place].id: result for place, result in enumerate(visited)
            if result is not None}
