"""Lost-line handlers: a program that may move in tracing mode 2 or 3 must define the
labels a lost guidance line jumps to (Table 4), or the run stops with a fault.

Only handlers that device.py found reachable are required: mode 3 with `(MOV ...)` alone
needs `:96`, not `:97`. This is a warning, not an error: the paper's own Listing 1 does
`(TRC 3); (MVI 1,1,50)` with no `:97`, and at run time the fault stops the vehicle.
"""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Fix, Severity

from .cfg import ControlFlowGraph
from .fixes import append_line

HANDLER = "(MOV 0,0); (END)"  # what the fix's handler does: stop, then end

_WHEN = {
    96: "in tracing mode 3, a lost line while `(MOV)` drives jumps to `:96`, the vehicle "
        "still moving",
    97: "in tracing mode 3, a lost line during `(MVI)` jumps to `:97`, the motion going on "
        "in the background",
    98: "in tracing mode 2, a lost line while `(MOV)` drives stops the vehicle and jumps "
        "to `:98`",
    99: "in tracing mode 2, a lost line during `(MVI)` aborts it and jumps to `:99`",
}


def check_handlers(program: ast.Program, graph: ControlFlowGraph) -> list[Diagnostic]:
    if any(block.opaque and not block.labels for block in graph.blocks):
        return []  # the line with a syntax error may define the handler
    first: dict[int, ast.Statement] = {}
    for block in graph.blocks:
        for edge in block.handlers:
            if edge.target is None and edge.label not in first:
                first[edge.label] = block.statements[edge.index]
    return [_missing(program, label, statement) for label, statement in sorted(first.items())]


def _missing(program: ast.Program, label: int, statement: ast.Statement) -> Diagnostic:
    handler = f":{label} {HANDLER}"
    return Diagnostic(
        "W0301", Severity.WARNING,
        f"a lost guidance line can jump to `:{label}` here, but no line starts with `:{label}`",
        statement.span,
        help=f"{_WHEN[label]}; without that label the run stops with a fault. Add the "
             f"handler, e.g. `{handler}`, or choose tracing mode 0 or 1 before moving",
        fixes=(Fix(f"add the handler `{handler}` at the end", (append_line(program, handler),)),),
    )
