"""The worklist solver shared by the forward data-flow analyses of the checker.

States are bitsets (ints) joined by `|`: each analysis asks "may this be so on some path
here?", so a block's state only grows and the solver stops after at most as many visits
per block as the state has bits. Works over blocks, not statements, and never recurses.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable

from .graph import ControlFlowGraph

# transfer(block index, state on entry) -> (state at its end, extra (block, state) edges)
Transfer = Callable[[int, int], tuple[int, Iterable[tuple[int, int]]]]


def solve(graph: ControlFlowGraph, start: int, transfer: Transfer) -> list[int]:
    """The state on entry to every block, starting from `start` at the entry block (0
    for blocks no path reaches). The state at a block's end flows to its successors; the
    extra edges carry their own states (lost-line handlers are entered mid-block)."""
    count = len(graph.blocks)
    states = [0] * count
    seen = bytearray(count)  # a state of 0 may be a real state: track visits apart
    seen[graph.entry] = True
    states[graph.entry] = start
    queued = bytearray(count)
    queued[graph.entry] = 1
    pending = deque([graph.entry])
    blocks = graph.blocks

    def join(target: int, state: int) -> None:
        joined = states[target] | state
        if joined != states[target] or not seen[target]:
            seen[target] = True
            states[target] = joined
            if not queued[target]:
                queued[target] = 1
                pending.append(target)

    while pending:
        index = pending.popleft()
        queued[index] = 0
        out, extra = transfer(index, states[index])
        for successor in blocks[index].successors:
            join(successor, out)
        for target, state in extra:
            join(target, state)
    return states
