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

from array import array

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Related, Severity

from .graph import ControlFlowGraph
from .scc import cycles

HELP = ("read a sensor inside the loop (e.g. `A=(IMG)-180`, `(KYO)`, `A=(ULT A)`) or wait "
        "with `(TIM t)`, so that it can see something change")


def check_loops(graph: ControlFlowGraph) -> list[Diagnostic]:
    blocks = graph.blocks
    blind = bytearray(graph.reachable(index) and not block.opaque and not block.handlers
                      and not block.effects.observes for index, block in enumerate(blocks))
    found: list[Diagnostic] = []
    # the blocks of the component looked at: a byte a block, where a set of a loop of
    # every block took 70 bytes a block
    members = bytearray(len(blocks))
    for component in cycles(lambda index: blocks[index].successors, blind):
        for index in component:
            members[index] = True
        # in order, as numbers in an array: a list of a loop of every block held an int
        # object a block while the rule ran
        diagnostic = _busy(graph, array("q", sorted(component)), members)
        if diagnostic is not None:
            found.append(diagnostic)
        for index in component:
            members[index] = False
    return found


def _busy(graph: ControlFlowGraph, loop: array[int], members: bytearray) -> Diagnostic | None:
    """W0604 for the cycle of the blocks numbered `loop` (in order), which `members`
    marks, if it is busy."""
    tested: set[str] = set()
    for index in loop:
        block = graph.blocks[index]
        jump = block.jump
        if isinstance(jump, ast.CondJump) and not all(members[successor]
                                                      for successor in block.successors):
            tested.add(jump.var.name)
    written = {statement.target.name for index in loop for statement in graph.statements(index)
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


def _backward_jump(graph: ControlFlowGraph, loop: array[int],
                   members: bytearray) -> tuple[ast.Goto | ast.CondJump, ast.LabelDef]:
    """The last jump back to a label inside the loop, and that label. Every cycle has
    one: fall-through only goes forward, and handler edges never leave a blind block."""
    for index in reversed(loop):
        jump = graph.blocks[index].jump
        number = jump.target.number if jump is not None else None
        target = graph.labels.get(number) if number is not None else None
        if jump is not None and target is not None and members[target] \
                and target <= index:
            head = next(label for label in graph.blocks[target].labels if label.number == number)
            # block.jump may stand for others' jumps (graph.Block.jump): the block's own
            written = graph.statements(index)[-1]
            assert isinstance(written, ast.Goto | ast.CondJump)
            return written, head
    raise AssertionError("a cycle without a backward jump")
