"""Semantic tokens, full and delta. A line's tokens depend on its text alone, so they
are remembered by text: after an edit only the changed lines are tokenised again."""

from __future__ import annotations

import itertools

from lsprotocol import types

from rl1.compiler import ast
from rl1.compiler.builtins import BUILTINS, RESERVED_VARIABLES

from .document import Document
from .positions import Columns

TOKEN_TYPES = ["label", "function", "enumMember", "variable", "number", "operator",
               "keyword", "comment"]
TOKEN_MODIFIERS = ["declaration", "defaultLibrary"]
LEGEND = types.SemanticTokensLegend(token_types=TOKEN_TYPES, token_modifiers=TOKEN_MODIFIERS)

(LABEL, FUNCTION, SELECTOR, VARIABLE, NUMBER, OPERATOR, KEYWORD, COMMENT) = range(8)
DECLARATION, DEFAULT_LIBRARY = 1, 2  # modifier bits

# (code-point column, code-point length, type, modifiers), 1-based columns
_Raw = tuple[int, int, int, int]

_MEMO_LIMIT = 200_000
_memo: dict[tuple[str, str], tuple[tuple[int, int, int, int], ...]] = {}


def _operand(operand: ast.Operand, out: list[_Raw]) -> None:
    if isinstance(operand, ast.Var):
        modifiers = DEFAULT_LIBRARY if operand.name in RESERVED_VARIABLES else 0
        out.append((operand.span.column, 1, VARIABLE, modifiers))
    elif isinstance(operand, ast.Const):
        out.append((operand.span.column, operand.span.end_column - operand.span.column, NUMBER, 0))
    else:
        span = operand.mnemonic_span
        known = operand.mnemonic.upper() in BUILTINS
        out.append((span.column, span.end_column - span.column, FUNCTION,
                    DEFAULT_LIBRARY if known else 0))
        for arg in operand.args:
            if isinstance(arg, ast.Selector):
                out.append((arg.span.column, 1, SELECTOR, 0))
            else:
                _operand(arg, out)


def _raw_tokens(line: ast.Line) -> list[_Raw]:
    out: list[_Raw] = []
    if line.label is not None:
        span = line.label.span
        out.append((span.column, span.end_column - span.column, LABEL, DECLARATION))
    for statement in line.statements:
        if isinstance(statement, ast.Assign):
            _operand(statement.target, out)
            _operand(statement.first, out)
            for step in statement.rest:
                out.append((step.op_span.column, 1, OPERATOR, 0))
                _operand(step.operand, out)
        elif isinstance(statement, ast.IncDec):
            _operand(statement.target, out)
            out.append((statement.target.span.end_column, 2, OPERATOR, 0))
        elif isinstance(statement, ast.CondJump):
            out.append((statement.span.column, 1, KEYWORD, 0))
            _operand(statement.var, out)
            out.append((statement.var.span.end_column, 1, OPERATOR, 0))
            target = statement.target.span
            out.append((target.column, target.end_column - target.column, LABEL, 0))
        elif isinstance(statement, ast.Goto):
            target = statement.target.span
            out.append((target.column, target.end_column - target.column, LABEL, 0))
        else:
            _operand(statement.call, out)
    if line.comment is not None:
        span = line.comment.span
        out.append((span.column, span.end_column - span.column, COMMENT, 0))
    out.sort()
    return out


def line_tokens(document: Document, number: int,
                columns: Columns) -> tuple[tuple[int, int, int, int], ...]:
    """(start, length, type, modifiers) in client units, 0-based start."""
    text = document.line_text(number)
    key = (text, columns.encoding)
    found = _memo.get(key)
    if found is None:
        if len(_memo) >= _MEMO_LIMIT:
            _memo.clear()
        found = tuple(
            (columns.to_client(text, column - 1),
             columns.to_client(text, column - 1 + length) - columns.to_client(text, column - 1),
             kind, modifiers)
            for column, length, kind, modifiers in _raw_tokens(document.line(number))
        )
        _memo[key] = found
    return found


def encode(document: Document, columns: Columns) -> list[int]:
    """The LSP integer encoding: each token relative to the one before."""
    data: list[int] = []
    previous_line = 0
    for number in range(1, document.program_lines() + 1):
        previous_start = 0
        for start, length, kind, modifiers in line_tokens(document, number, columns):
            data += (number - 1 - previous_line, start - previous_start, length, kind, modifiers)
            previous_line, previous_start = number - 1, start
    return data


class TokenHistory:
    """The last tokens sent for each document, for delta requests."""

    def __init__(self) -> None:
        self._sent: dict[str, tuple[str, list[int]]] = {}
        self._ids = itertools.count(1)

    def full(self, document: Document, columns: Columns) -> types.SemanticTokens:
        data = encode(document, columns)
        result_id = str(next(self._ids))
        self._sent[document.uri] = (result_id, data)
        return types.SemanticTokens(data=data, result_id=result_id)

    def delta(self, document: Document, columns: Columns,
              previous_id: str) -> types.SemanticTokens | types.SemanticTokensDelta:
        previous = self._sent.get(document.uri)
        if previous is None or previous[0] != previous_id:
            return self.full(document, columns)
        old = previous[1]
        new = self.full(document, columns)
        data = new.data
        start = 0
        limit = min(len(old), len(data))
        while start < limit and old[start] == data[start]:
            start += 1
        end = 0
        while end < limit - start and old[-1 - end] == data[-1 - end]:
            end += 1
        edits = [] if old == data else [types.SemanticTokensEdit(
            start=start, delete_count=len(old) - start - end,
            data=data[start : len(data) - end])]
        return types.SemanticTokensDelta(edits=edits, result_id=new.result_id)

    def forget(self, uri: str) -> None:
        self._sent.pop(uri, None)
