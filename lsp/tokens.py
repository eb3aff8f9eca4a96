"""Semantic tokens, full and delta. A line's tokens depend on its text alone, so they
are remembered by text: after an edit only the changed lines are tokenised again."""

from __future__ import annotations

import itertools

from lsprotocol import types

from rl1.compiler.frontend import ast
from rl1.vm.language import BUILTINS, RESERVED_VARIABLES

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
_memo: dict[tuple[str, str], tuple[int, ...]] = {}


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


def _line_data(document: Document, number: int, columns: Columns) -> tuple[int, ...]:
    """A line's tokens in the LSP encoding, less the first token's line delta (the one
    number that depends on the lines before): start, length, type, modifiers, then
    0, start delta, length, type, modifiers for each further token."""
    text = document.line_text(number)
    key = (text, columns.encoding)
    found = _memo.get(key)
    if found is None:
        if len(_memo) >= _MEMO_LIMIT:
            _memo.clear()
        data: list[int] = []
        previous = 0
        for column, length, kind, modifiers in _raw_tokens(document.line(number)):
            start = columns.to_client(text, column - 1)
            end = columns.to_client(text, column - 1 + length)
            data += (0, start - previous, end - start, kind, modifiers)
            previous = start
        found = _memo[key] = tuple(data[1:])
    return found


def encode(document: Document, columns: Columns) -> list[int]:
    """The LSP integer encoding: each token relative to the one before."""
    data: list[int] = []
    previous_line = 0
    for number in range(1, document.program_lines() + 1):
        line_data = _line_data(document, number, columns)
        if line_data:
            data.append(number - 1 - previous_line)
            data += line_data
            previous_line = number - 1
    return data


def _common_prefix(old: list[int], new: list[int]) -> int:
    """How many leading items the lists share, compared a block at a time in C."""
    limit = min(len(old), len(new))
    same, block = 0, 4096
    while same < limit:
        step = min(block, limit - same)
        if old[same : same + step] == new[same : same + step]:
            same += step
        elif step == 1:
            break
        else:
            block = max(step // 2, 1)
    return same


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
        data = list(new.data)
        start = _common_prefix(old, data)
        end = min(_common_prefix(old[::-1], data[::-1]), len(old) - start, len(data) - start)
        edits = [] if old == data else [types.SemanticTokensEdit(
            start=start, delete_count=len(old) - start - end,
            data=data[start : len(data) - end])]
        return types.SemanticTokensDelta(edits=edits, result_id=new.result_id)

    def forget(self, uri: str) -> None:
        self._sent.pop(uri, None)
