"""Strongly connected components (Tarjan's algorithm, with an explicit stack so that a
100,000-line program cannot exhaust Python's recursion limit)."""

from __future__ import annotations

from collections.abc import Sequence


def cycles(successors: Sequence[Sequence[int]], included: Sequence[bool]) -> list[list[int]]:
    """The components of the subgraph of `included` nodes that hold a cycle: more than
    one node, or one node with an edge to itself."""
    count = len(successors)
    order = [-1] * count  # discovery number, -1 while undiscovered
    low = [0] * count
    on_stack = [False] * count
    stack: list[int] = []
    found: list[list[int]] = []
    counter = 0
    for root in range(count):
        if not included[root] or order[root] >= 0:
            continue
        order[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack[root] = True
        work = [(root, 0)]  # (node, index of its next successor to look at)
        while work:
            node, position = work[-1]
            following = successors[node]
            if position < len(following):
                work[-1] = (node, position + 1)
                successor = following[position]
                if not included[successor]:
                    continue
                if order[successor] < 0:
                    order[successor] = low[successor] = counter
                    counter += 1
                    stack.append(successor)
                    on_stack[successor] = True
                    work.append((successor, 0))
                elif on_stack[successor]:
                    low[node] = min(low[node], order[successor])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == order[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack[member] = False
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1 or node in following:
                    found.append(component)
    return found
