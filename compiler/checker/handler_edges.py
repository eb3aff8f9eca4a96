"""The lost-line handler edges of the control-flow graph: one forward data-flow over the
graph (dataflow.py) of device.py's state (the tracing mode and the motion that may be in
effect) gives, for each block, the state on entry and the handlers `:96`-`:99` a lost
guidance line may jump to from it (Table 4, language.LOST_LINE_RULES)."""

from __future__ import annotations

from . import dataflow, device
from .graph import ControlFlowGraph, HandlerEdge


def add_handler_edges(graph: ControlFlowGraph) -> None:
    """Fill in the graph's device state on entry to each block and its handler edges."""
    graph.device_on_entry, triggers = trace(graph)
    for block, found in zip(graph.blocks, triggers, strict=True):
        # a block the incremental check took over may hold the last check's edges
        block.handlers = tuple(HandlerEdge(label, index, graph.labels.get(label))
                               for label, (index, _) in sorted(found.items()))


def trace(graph: ControlFlowGraph) -> tuple[list[int], list[device.Triggers]]:
    """The state on entry to every block (0: unreachable) and, per block, the handlers a
    lost line may jump to from it."""
    blocks = graph.blocks
    # one empty dict for all the blocks without triggers (those no path reaches among
    # them): a visit replaces a block's, none is changed; a dict a block was 64 bytes a
    # block of a program of thousands
    none: device.Triggers = {}
    triggers = [none] * len(blocks)

    def transfer(index: int, state: int) -> tuple[int, list[tuple[int, int]]]:
        block = blocks[index]
        if block.opaque:
            return device.START, []
        # A block's last visit is with its final state, so its last triggers are final.
        effects = block.effects
        out, found = device.run(effects.operations, effects.first_event, state)
        triggers[index] = found or none
        return out, [(graph.labels[label], entry)
                     for label, (_, entry) in triggers[index].items() if label in graph.labels]

    return dataflow.solve(graph, device.START, transfer), triggers
