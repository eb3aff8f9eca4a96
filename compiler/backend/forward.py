"""The forward data flow that constant folding (constants.py) and the signs of branches
(signs.py) both run: what is known where each block starts, from what its predecessors
know where their edges leave them, until nothing changes.

A worklist in layout order from the roots (flow.roots), each block queued once at a
time; a block is visited again only when what is known where it starts changed. A
visit may decide that an edge is not taken (a branch on a known value): only the edges
the last visit gave count, so code behind a way never taken learns nothing from it.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable, Iterator
from typing import TypeVar

from . import flow, ir

State = TypeVar("State")
Visited = TypeVar("Visited")


def solve(program: ir.Program, *, entry: State, handler: State,
          combine: Callable[[list[State]], State],
          visit: Callable[[ir.Block, State], Visited],
          edges: Callable[[ir.Block, Visited], Iterable[tuple[ir.BlockId, State]]]
          ) -> dict[ir.BlockId, Visited]:
    """What `visit` gives for each block some path reaches, from what is known where it
    starts: `combine` of what `entry` (the program's start) or `handler` (a handler's
    start, where an event arrives from anywhere) say and of the states the `edges` of
    the visits of its predecessors lead into it with.

    What the flow holds of each block is in lists by its place in the layout, and what
    leads into a block is found again from its predecessors' last visits (`edges`), not
    held: a block a line of `?A<#01` held 400 bytes of the flow's dictionaries and
    lists, 57 bytes a source byte."""
    places = flow.Places(program)
    blocks, place_of = places.blocks, places.place
    starts: dict[int, list[State]] = {}  # the roots' own states
    starts.setdefault(place_of[program.entry], []).append(entry)
    for block_id in program.handlers.values():
        starts.setdefault(place_of[block_id], []).append(handler)
    entries: list[State | None] = [None] * len(blocks)  # what its last visit started from
    visited: list[Visited | None] = [None] * len(blocks)
    work = deque(place_of[block_id] for block_id in flow.roots(program))
    queued = bytearray(len(blocks))
    for place in work:
        queued[place] = 1
    while work:
        place = work.popleft()
        queued[place] = 0
        known = combine([*starts.get(place, ()), *_incoming(place, places, visited, edges)])
        if entries[place] == known:
            continue
        entries[place] = known
        block = blocks[place]
        visited[place] = after = visit(block, known)
        for target_id, _ in edges(block, after):
            target = place_of[target_id]
            if not queued[target]:
                queued[target] = 1
                work.append(target)
    del entries
    return {blocks[place].id: result for place, result in enumerate(visited)
            if result is not None}


def _incoming(place: int, places: flow.Places, visited: list[Visited | None],
              edges: Callable[[ir.Block, Visited], Iterable[tuple[ir.BlockId, State]]]
              ) -> Iterator[State]:
    """The states the last visits of the block's predecessors lead into it with: their
    edges again (held, they were 56 bytes a block)."""
    block_id = places.blocks[place].id
    for pred in places.predecessors(place):
        last = visited[pred]
        if last is not None:
            for target, leaving in edges(places.blocks[pred], last):
                if target == block_id:
                    yield leaving
