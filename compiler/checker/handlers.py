"""Lost-line handlers: a program that may move in tracing mode 2 or 3 must define the
labels a lost guidance line jumps to (Table 4), or the run stops with a fault.

Only handlers that device.py found reachable are required: mode 3 with `(MOV ...)` alone
needs `:96`, not `:97`. This is a warning, not an error: the paper's own Listing 1 does
`(TRC 3); (MVI 1,1,50)` with no `:97`, and at run time the fault stops the vehicle.
"""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Fix, Severity
from rl1.vm.language import LOST_LINE_RULES

from .fixes import append_line
from .graph import ControlFlowGraph

HANDLER = "(MOV 0,0); (END)"  # what the fix's handler does: stop, then end

_DURING = {"MOV": "while `(MOV)` drives", "MVI": "during `(MVI)`"}
_THEN = {  # (stops, command): what the lost line does besides the jump
    (True, "MOV"): "stops the vehicle and jumps to `:{label}`",
    (True, "MVI"): "aborts it and jumps to `:{label}`",
    (False, "MOV"): "jumps to `:{label}`, the vehicle still moving",
    (False, "MVI"): "jumps to `:{label}`, the motion going on in the background",
}
_WHEN = {
    rule.label: f"in tracing mode {rule.mode}, a lost line {_DURING[rule.command]} "
                + _THEN[rule.stops, rule.command].format(label=rule.label)
    for rule in LOST_LINE_RULES
}


def check_handlers(program: ast.Span, graph: ControlFlowGraph) -> list[Diagnostic]:
    if any(block.opaque and not block.labels for block in graph.blocks):
        return []  # the line with a syntax error may define the handler
    first: dict[int, ast.Statement] = {}
    for index, block in enumerate(graph.blocks):
        for edge in block.handlers:
            if edge.target is None and edge.label not in first:
                first[edge.label] = graph.statements(index)[edge.statement]
    return [_missing(program, label, statement) for label, statement in sorted(first.items())]


def _missing(program: ast.Span, label: int, statement: ast.Statement) -> Diagnostic:
    handler = f":{label} {HANDLER}"
    return Diagnostic(
        "W0301", Severity.WARNING,
        f"a lost guidance line can jump to `:{label}` here, but no line starts with `:{label}`",
        statement.span,
        help=f"{_WHEN[label]}; without that label the run stops with a fault. Add the "
             f"handler, e.g. `{handler}`, or choose tracing mode 0 or 1 before moving",
        fixes=(Fix(f"add the handler `{handler}` at the end", (append_line(program, handler),)),),
    )
