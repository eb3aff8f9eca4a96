"""The formatter: RL/I source in the canonical layout of spec/language.md, section 11.

Each line is re-printed from its parse tree, so the layout depends only on what the line
means; a line with a syntax error has no tree and is kept exactly as written. The output
has one line per input line, so positions keep their line numbers: the language server's
range formatting (`format_lines`) and the whole-document form (`format_text`) agree.
"""

from __future__ import annotations

from .frontend import ast
from .frontend.diagnostics import Edit
from .frontend.parser import parse_line
from .frontend.source import LINE_BREAK, split_lines


def format_line(text: str) -> str:
    """One line (without its line end) in the canonical layout."""
    line, _ = parse_line(text, 1)
    if not line.ok:
        return text
    parts = [line.label.text] if line.label else []
    if line.statements:
        parts.append("; ".join(_statement(statement) for statement in line.statements))
    if line.comment:
        parts.append("'" + line.comment.text)
    return " ".join(parts)


def format_text(text: str) -> str:
    """A whole document in the canonical layout: every line formatted, blank lines at
    the end dropped, every line ended as the document's first line end is."""
    lines = [format_line(line) for line in split_lines(text)]
    while lines and not lines[-1]:
        lines.pop()
    if not lines:
        return ""
    first_end = LINE_BREAK.search(text)
    line_end = first_end.group() if first_end else "\n"
    return line_end.join(lines) + line_end


def format_lines(text: str, first_line: int, last_line: int) -> list[Edit]:
    """The edits that put lines `first_line`..`last_line` (1-based, inclusive; clipped
    to the document) in the canonical layout. Each edit replaces one line's text, never
    its line end; lines already canonical get none."""
    lines = split_lines(text)
    edits = []
    for number in range(max(first_line, 1), min(last_line, len(lines)) + 1):
        old = lines[number - 1]
        new = format_line(old)
        if new != old:
            edits.append(Edit(ast.Span(number, 1, number, len(old) + 1), new))
    return edits


# Printing the tree -----------------------------------------------------------------------


def _statement(statement: ast.Statement) -> str:
    match statement:
        case ast.Assign():
            steps = "".join(step.op + _operand(step.operand) for step in statement.rest)
            return f"{statement.target.name}={_operand(statement.first)}{steps}"
        case ast.IncDec():
            return statement.target.name + statement.step
        case ast.Goto():
            return statement.target.text
        case ast.CondJump():
            return f"?{statement.var.name}{statement.relation}{statement.target.text}"
        case ast.CallStmt():
            return _call(statement.call)


def _operand(operand: ast.Operand) -> str:
    if isinstance(operand, ast.Call):
        return _call(operand)
    return _arg(operand)


def _arg(arg: ast.Arg) -> str:
    match arg:
        case ast.Var():
            return arg.name
        case ast.Const():
            return arg.text
        case ast.Selector():
            return arg.letter


def _call(call: ast.Call) -> str:
    """`(MOV 3,3)`, `(CAM A 90)`: a selector is followed by a space, other arguments by
    commas. After a selector, a negative number needs the comma: `(CAM A -5)` would scan
    as the letter minus 5."""
    text = "(" + call.mnemonic
    for index, arg in enumerate(call.args):
        written = _arg(arg)
        after_selector = index > 0 and isinstance(call.args[index - 1], ast.Selector)
        if index == 0 or (after_selector and not written.startswith("-")):
            text += " " + written
        else:
            text += "," + written
    return text + ")"
