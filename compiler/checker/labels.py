"""Label rules over the whole program: jumps to labels nobody defines, labels defined
twice, labels nobody jumps to.

A line with a syntax error may have defined a label or jumped to one, so while the
program has such a line (and the parser could not recover its label), undefined and
unused labels are not reported: they are likely cascades of that error.
"""

from __future__ import annotations

import operator
from collections.abc import Callable, Collection

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Edit, Fix, Related, Severity
from rl1.vm.language import HANDLER_LABELS

from .graph import ControlFlowGraph

OnUndefined = Callable[[int, str], None]
"""Told of the number of a block whose jump goes to a label no line defines, with what E0203's help
says of the labels defined (the same for every one)."""


def check_labels(graph: ControlFlowGraph, on_undefined: OnUndefined | None = None
                 ) -> list[Diagnostic]:
    """The label diagnostics of `graph`; with `on_undefined`, the number of each block
    whose jump's target E0203 would report is handed to it instead (the streaming check
    holds them compactly: a source of jumps to a missing label has one a line)."""
    found: list[Diagnostic] = []
    first: dict[int, ast.LabelDef] = {}
    for index in graph.labelled:
        for label in graph.blocks[index].labels:
            if label.number is None:
                continue
            if label.number in first:
                found.append(_defined_twice(label, first[label.number]))
            else:
                first[label.number] = label

    jumps = list(filter(None, map(operator.attrgetter("jump"), graph.blocks)))
    targets = {jump.target.number for jump in jumps}
    blind = any(not graph.blocks[index].labels for index in graph.opaque)
    missing = {number for number in targets if number is not None and number not in first}
    if missing and not blind:
        defined = _defined(first)

        def report(index: int, defined: str) -> None:
            # a block's jump may stand for others' (graph.Block.jump): its place is that
            # of the block's last statement
            found.append(_undefined(_written(graph.statements(index)[-1]), defined))

        undefined = report if on_undefined is None else on_undefined
        for index, block in enumerate(graph.blocks):
            if block.jump is not None and block.jump.target.number in missing:
                undefined(index, defined)
    if not graph.opaque:
        found.extend(_unused(graph, number, label) for number, label in first.items()
                     if number not in targets and number not in HANDLER_LABELS)
    return found


def _written(jump: ast.Statement) -> ast.LabelRef:
    """The target of the jump a block ends with, as written."""
    assert isinstance(jump, ast.Goto | ast.CondJump)
    return jump.target


def _defined_twice(label: ast.LabelDef, earlier: ast.LabelDef) -> Diagnostic:
    return Diagnostic(
        "E0204", Severity.ERROR, f"the label `{label.text}` is defined twice", label.span,
        help=f"every jump to `#{label.text[1:]}` goes to the first definition: "
             "give this one another number",
        related=(Related(earlier.span, f"`{label.text}` is first defined here"),),
    )


def undefined_targets(line: ast.Line, columns: Collection[int], defined: str
                      ) -> list[Diagnostic]:
    """The E0203s of the jumps in `line` whose targets are at `columns`, which
    check_labels reported with `defined`: built again from the line (compact.py)."""
    return [_undefined(statement.target, defined) for statement in line.statements
            if isinstance(statement, ast.Goto | ast.CondJump)
            and statement.target.span.column in columns]


def _defined(first: dict[int, ast.LabelDef]) -> str:
    """What E0203's help says of the labels `first` defines."""
    if not first:
        return ""
    listed = ", ".join(f"`{label.text}`" for _, label in sorted(first.items())[:12])
    more = ", ..." if len(first) > 12 else ""
    return f"; the labels defined are {listed}{more}"


def _undefined(ref: ast.LabelRef, defined: str) -> Diagnostic:
    help_text = f"start the line to jump to with `:{ref.text[1:]}`{defined}"
    return Diagnostic("E0203", Severity.ERROR,
                      f"the jump target `{ref.text}` is not defined: no line starts with "
                      f"`:{ref.text[1:]}`", ref.span, help=help_text)


def _unused(graph: ControlFlowGraph, number: int, label: ast.LabelDef) -> Diagnostic:
    following = [statement.span for statement in graph.statements(graph.labels[number])[:1]
                 if statement.span.line == label.span.line]
    end = following[0] if following else label.span
    removal = ast.Span(label.span.line, label.span.column, end.line,
                       end.column if following else end.end_column)
    return Diagnostic(
        "W0205", Severity.WARNING, f"the label `{label.text}` is never jumped to", label.span,
        help=f"no `#{label.text[1:]}` or `?V..#{label.text[1:]}` jumps here: remove the label, "
             "or jump to it",
        fixes=(Fix(f"remove `{label.text}`", (Edit(removal, ""),)),),
    )
