"""Mechanical fixes that several rules offer."""

from __future__ import annotations

from .. import ast
from ..diagnostics import Edit


def append_line(program: ast.Program, text: str) -> Edit:
    """Add a line after the program's last line."""
    end = program.span
    return Edit(ast.Span(end.end_line, end.end_column, end.end_line, end.end_column), "\n" + text)
