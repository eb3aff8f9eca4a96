"""Ending while the vehicle moves: `(END)` does not stop the motion a `(MOV ...)` started,
nor an `(MVI ...)` that a lost line in tracing mode 3 left running in the background
(nor does running off the last line), so a program that ends on such a path leaves the
vehicle driving with nothing in control."""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Edit, Fix, Severity

from . import device
from .fixes import append_line
from .graph import ControlFlowGraph
from .reachability import fall_off_span

HELP = ("`(END)` does not stop the motion a `(MOV)` started, nor an `(MVI)` going on in the "
        "background: stop the vehicle first with `(MOV 0,0)`, `(HLD)` or `(FRE)`")
MOVING = device.MOVING | device.RUNNING  # a MOV in effect, or an MVI in the background


def check_safety(program: ast.Span, graph: ControlFlowGraph) -> list[Diagnostic]:
    found: list[Diagnostic] = []
    for index, (block, entry) in enumerate(zip(graph.blocks, graph.device_on_entry,
                                               strict=True)):
        if not (entry and block.ends):
            continue
        state = device.run(block.effects.operations, block.effects.first_event, entry)[0]
        if state & MOVING:
            end = graph.statements(index)[-1].span
            found.append(Diagnostic(
                "W0701", Severity.WARNING, f"the program can end here {_while(state)}", end,
                help=HELP,
                fixes=(Fix("stop before `(END)`", (Edit(ast.Span(
                    end.line, end.column, end.line, end.column), "(MOV 0,0); "),)),),
            ))
    span = fall_off_span(graph)
    state = graph.device_on_entry[graph.exit]
    if state & MOVING and span is not None:
        found.append(Diagnostic(
            "W0701", Severity.WARNING,
            f"the program can run off its end here {_while(state)}", span,
            help=HELP + "; running off the last line ends the program like `(END)`",
            fixes=(Fix("stop at the end", (append_line(program, "(MOV 0,0)"),)),),
        ))
    return found


def _while(state: int) -> str:
    if state & device.MOVING:
        return "while the vehicle is still moving"
    return ("while an `(MVI)` that a lost line left running in the background (tracing "
            "mode 3) still drives the vehicle")
