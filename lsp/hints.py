"""Inlay hints: the parameter name before each argument of a call, `(MVI l: 3, r: 3,
cm: 50)`, shown by the editor, never written into the text."""

from __future__ import annotations

from lsprotocol import types

from rl1.compiler.frontend import ast
from rl1.vm.language import BUILTINS

from .document import Document
from .positions import Columns


def _calls(line: ast.Line) -> list[ast.Call]:
    found = []
    for statement in line.statements:
        if isinstance(statement, ast.CallStmt):
            found.append(statement.call)
        elif isinstance(statement, ast.Assign):
            operands = [statement.first, *(step.operand for step in statement.rest)]
            found += [operand for operand in operands if isinstance(operand, ast.Call)]
    return found


def inlay_hints(document: Document, requested: types.Range,
                columns: Columns) -> list[types.InlayHint]:
    first = max(requested.start.line, 0) + 1
    last = min(requested.end.line + 1, document.program_lines())
    hints = []
    for number in range(first, last + 1):
        text = document.line_text(number)
        for call in _calls(document.line(number)):
            builtin = BUILTINS.get(call.mnemonic.upper())
            if builtin is None:
                continue
            args = list(call.args)
            selector = None
            if builtin.has_selector and args and isinstance(args[0], ast.Selector):
                selector = args[0].letter.upper()
                args = args[1:]
            form = builtin.form(selector)
            if form is None:
                continue
            for param, arg in zip(form.params, args, strict=False):
                hints.append(types.InlayHint(
                    position=types.Position(number - 1,
                                            columns.to_client(text, arg.span.column - 1)),
                    label=f"{param.name}:",
                    kind=types.InlayHintKind.Parameter,
                    padding_right=True,
                    tooltip=param.describe(),
                ))
    return hints
