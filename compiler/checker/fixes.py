"""Mechanical fixes that several rules offer."""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Edit


def append_line(program: ast.Program, text: str) -> Edit:
    """Add a line after the program's last line."""
    end = program.span
    return Edit(ast.Span(end.end_line, end.end_column, end.end_line, end.end_column), "\n" + text)
