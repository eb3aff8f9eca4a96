"""Busy loops: cycles of the CFG that can never see the world change.

A cycle is blind when none of its blocks makes an observing call (effects.py), none can
be left by a lost guidance line (a handler edge), and none is a line the parser could not
read. A blind cycle still ends if one of its exits tests a variable it changes (a
counting loop); the rule reports it when it has no exit, or when every exit tests only
variables that nothing in the loop writes: once such a loop goes round, it goes round
forever. Cycles are found as strongly connected components of the blind blocks, so
nested blind loops are reported once, on their last backward jump.
"""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Related, Severity

from .graph import Block, ControlFlowGraph
from .scc import cycles

HELP = ("read a sensor inside the loop (e.g. `A=(IMG)-180`, `(KYO)`, `A=(ULT A)`) or wait "
        "with `(TIM t)`, so that it can see something change")


def check_loops(graph: ControlFlowGraph) -> list[Diagnostic]:
    blocks = graph.blocks
    blind = [graph.reachable(block.index) and not block.opaque and not block.handlers
             and not block.effects.observes for block in blocks]
    found: list[Diagnostic] = []
    for component in cycles([block.successors for block in blocks], blind):
        members = set(component)
        diagnostic = _busy(graph, [blocks[index] for index in sorted(component)], members)
        if diagnostic is not None:
            found.append(diagnostic)
    return found


def _busy(graph: ControlFlowGraph, loop: list[Block], members: set[int]) -> Diagnostic | None:
    tested: set[str] = set()
    for block in loop:
        jump = block.jump
        if isinstance(jump, ast.CondJump) and not set(block.successors) <= members:
            tested.add(jump.var.name)
    written = {statement.target.name for block in loop for statement in block.statements
               if isinstance(statement, ast.Assign | ast.IncDec)}
    if tested & written:
        return None
    back, head = _backward_jump(graph, loop, members)
    if tested:
        names = " or ".join(f"`{name}`" for name in sorted(tested))
        message = (f"this loop never reads a sensor or waits, and nothing in it changes "
                   f"{names}: once it goes round, it goes round forever")
    else:
        message = "this loop has no way out and never reads a sensor or waits: the program hangs"
    return Diagnostic("W0604", Severity.WARNING, message, back.span, help=HELP,
                      related=(Related(head.span, "the loop starts here"),))


def _backward_jump(graph: ControlFlowGraph, loop: list[Block],
                   members: set[int]) -> tuple[ast.Goto | ast.CondJump, ast.LabelDef]:
    """The last jump back to a label inside the loop, and that label. Every cycle has
    one: fall-through only goes forward, and handler edges never leave a blind block."""
    for block in reversed(loop):
        jump = block.jump
        number = jump.target.number if jump is not None else None
        target = graph.labels.get(number) if number is not None else None
        if jump is not None and target is not None and target in members \
                and target <= block.index:
            head = next(label for label in graph.blocks[target].labels if label.number == number)
            return jump, head
    raise AssertionError("a cycle without a backward jump")
