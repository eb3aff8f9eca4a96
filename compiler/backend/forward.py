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
from collections.abc import Callable, Iterable
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
    the visits of its predecessors lead into it with."""
    starts: dict[ir.BlockId, list[State]] = {block_id: [] for block_id in program.blocks}
    starts[program.entry].append(entry)
    for block_id in program.handlers.values():
        starts[block_id].append(handler)
    # For each block, what each predecessor visited so far knows where it leads there.
    incoming: dict[ir.BlockId, dict[ir.BlockId, State]] = {
        block_id: {} for block_id in program.blocks}
    entries: dict[ir.BlockId, State] = {}
    visited: dict[ir.BlockId, Visited] = {}
    leads_to: dict[ir.BlockId, list[ir.BlockId]] = {}  # the targets of each last visit
    work = deque(flow.roots(program))
    queued = set(work)
    while work:
        block_id = work.popleft()
        queued.discard(block_id)
        known = combine([*starts[block_id], *incoming[block_id].values()])
        if block_id in entries and entries[block_id] == known:
            continue
        entries[block_id] = known
        block = program.blocks[block_id]
        for target in leads_to.get(block_id, ()):
            incoming[target].pop(block_id, None)
        visited[block_id] = after = visit(block, known)
        targets = leads_to[block_id] = []
        for target, leaving in edges(block, after):
            targets.append(target)
            incoming[target][block_id] = leaving
            if target not in queued:
                queued.add(target)
                work.append(target)
    return visited
