"""Mechanical fixes that several rules offer."""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Edit


def append_line(program: ast.Span, text: str) -> Edit:
    """Add a line after the program's last line (`program` is the program's span)."""
    return Edit(ast.Span(program.end_line, program.end_column, program.end_line,
                         program.end_column), "\n" + text)
