"""Code that never runs, and programs that end only by running off their last line.

Unreachable code is reported once per run of consecutive blocks no path reaches: as code
after `(END)` (W0602) when the run starts right after an `(END)` on the same straight
line, otherwise as unreachable (W0601), saying why: it follows a jump, or no path jumps
to its label. The code of a lost-line handler `:96`-`:99` is not reported: the device
jumps there.
"""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Fix, Severity
from rl1.vm.language import HANDLER_LABELS

from .fixes import append_line
from .graph import ControlFlowGraph

REMOVE_OR_LABEL = "remove it, or start its line with a label and jump there"


def check_reachability(program: ast.Span, graph: ControlFlowGraph) -> list[Diagnostic]:
    found: list[Diagnostic] = []
    run = 0  # where the run of blocks no path reaches starts, if one has started
    defensive = _handler_code(graph)
    for index, entry in enumerate(graph.device_on_entry):
        if entry or index in defensive:
            if run < index:
                found.extend(_unreachable(graph, range(run, index)))
            run = index + 1
    if run < len(graph.blocks):
        found.extend(_unreachable(graph, range(run, len(graph.blocks))))
    found.extend(_no_end(program, graph))
    return found


def _handler_code(graph: ControlFlowGraph) -> set[int]:
    """The blocks of handlers `:96`-`:99` that no lost line reaches as the program is:
    a handler defined defensively is there for the device, which may lose the line in a
    mode the checker did not foresee (or after an edit), so its code is not dead."""
    stack = [graph.labels[label] for label in HANDLER_LABELS if label in graph.labels]
    found: set[int] = set()
    while stack:
        index = stack.pop()
        if index not in found and not graph.reachable(index):
            found.add(index)
            stack.extend(graph.blocks[index].successors)
    return found


def _unreachable(graph: ControlFlowGraph, run: range) -> list[Diagnostic]:
    """W0601 or W0602 for the blocks numbered `run`, which no path reaches."""
    # the first and last statements only: a run may be most of the program
    first_statement = next((statements[0] for statements in map(graph.statements, run)
                            if statements), None)
    last_statement = next((statements[-1] for statements in map(graph.statements, reversed(run))
                           if statements), None)
    if first_statement is None or last_statement is None:
        return []  # only lines with syntax errors
    span = first_statement.span.cover(last_statement.span)
    first = graph.blocks[run[0]]
    before = graph.statements(run[0] - 1)[-1:]  # the entry block is reachable
    if first.labels:
        label = first.labels[-1].text
        return [Diagnostic("W0601", Severity.WARNING,
                           f"this code never runs: no jump that runs goes to `{label}`, and "
                           "the code before it never continues here", span,
                           help=f"remove it, or jump to `{label}` from code that runs")]
    if before and isinstance(before[0], ast.Goto):
        return [Diagnostic("W0601", Severity.WARNING,
                           f"this code follows the jump `{before[0].target.text}`, so it never "
                           "runs",
                           span, help=REMOVE_OR_LABEL)]
    return [Diagnostic("W0602", Severity.WARNING, "this code follows `(END)`, so it never runs",
                       span, help=REMOVE_OR_LABEL)]


def _no_end(program: ast.Span, graph: ControlFlowGraph) -> list[Diagnostic]:
    """W0603: no `(END)` anywhere, and the program can run off its last line."""
    blocks = graph.blocks
    if not graph.reachable(graph.exit) or any(block.ends or block.opaque for block in blocks):
        return []
    if any(block.effects.calls_unknown for block in blocks):
        return []  # a misspelt `(ENDD)` is reported as such (E0501): it may be the (END)
    span = fall_off_span(graph)
    if span is None:
        return []  # nothing runs at all
    return [Diagnostic(
        "W0603", Severity.WARNING, "the program has no `(END)`: it ends by running off its "
        "last line", span,
        help="running off the end behaves as `(END)`; write `(END)` where the program stops, "
             "so that a reader sees it",
        fixes=(Fix("add `(END)` at the end", (append_line(program, "(END)"),), safe=True),),
    )]


def fall_off_span(graph: ControlFlowGraph) -> ast.Span | None:
    """Where the program runs off its end: the label at the very end naming no code, or
    else the last statement; None for a program with neither."""
    exit_block = graph.blocks[graph.exit]
    if exit_block.labels:
        return exit_block.labels[-1].span
    for index in reversed(range(len(graph.blocks))):
        if statements := graph.statements(index):
            return statements[-1].span
    return None
