"""Strongly connected components (Tarjan's algorithm, with an explicit stack so that a
100,000-line program cannot exhaust Python's recursion limit). Its numbers are held in
arrays: a program of a block a line has as many nodes as lines, and a list of ints
took 64 bytes a node for their objects alone (bench/memory.py's jumps)."""

from __future__ import annotations

from array import array
from collections.abc import Callable, Sequence


def cycles(successors: Callable[[int], Sequence[int]], included: Sequence[int]
           ) -> list[array[int]]:
    """The components of the subgraph of `included` nodes (nonzero there: a bytearray
    does) that hold a cycle: more than one node, or one node with an edge to itself.
    `successors` gives a node's, looked up as they are needed (a list of them all took
    8 bytes a node)."""
    count = len(included)
    order = array("i", [-1]) * count  # discovery number, -1 while undiscovered
    low = array("i", [0]) * count
    on_stack = bytearray(count)
    stack = array("q")
    found: list[array[int]] = []
    counter = 0
    for root in range(count):
        if not included[root] or order[root] >= 0:
            continue
        order[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack[root] = True
        # the path being walked: its nodes, and the index of each one's next successor
        # to look at
        work, positions = array("q", [root]), array("q", [0])
        while work:
            node, position = work[-1], positions[-1]
            following = successors(node)
            if position < len(following):
                positions[-1] = position + 1
                successor = following[position]
                if not included[successor]:
                    continue
                if order[successor] < 0:
                    order[successor] = low[successor] = counter
                    counter += 1
                    stack.append(successor)
                    on_stack[successor] = True
                    work.append(successor)
                    positions.append(0)
                elif on_stack[successor]:
                    low[node] = min(low[node], order[successor])
                continue
            work.pop()
            positions.pop()
            if work:
                parent = work[-1]
                low[parent] = min(low[parent], low[node])
            if low[node] == order[node]:
                component = array("q")
                while True:
                    member = stack.pop()
                    on_stack[member] = False
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1 or node in following:
                    found.append(component)
    return found
