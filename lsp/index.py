"""What the features ask of the program: the token under the cursor, and where each
label is defined and jumped to."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

from rl1.compiler.frontend import ast

from .document import Document

Token = ast.Var | ast.Const | ast.Selector | ast.LabelDef | ast.LabelRef | ast.Call


def tokens(line: ast.Line) -> list[Token]:
    """The tokens of a line that features know about, in source order. A call stands for
    its mnemonic (`token_span` gives the mnemonic's span)."""
    return [node for node in ast.walk(line) if isinstance(node, Token)]


def token_span(token: Token) -> ast.Span:
    return token.mnemonic_span if isinstance(token, ast.Call) else token.span


def token_at(line: ast.Line, column: int) -> Token | None:
    """The token under 1-based `column`, or the one just before it (a cursor at the end
    of `#10` still means `#10`)."""
    found = tokens(line)
    for token in found:
        if token_span(token).contains(line.number, column):
            return token
    return next((t for t in found if token_span(t).end_column == column), None)


@dataclass(frozen=True, slots=True)
class Labels:
    """Every label definition and every jump, by label number."""

    definitions: dict[int, list[ast.LabelDef]]
    jumps: dict[int, list[ast.LabelRef]]

    def defined(self) -> list[int]:
        return sorted(self.definitions)


def labels(document: Document) -> Labels:
    """The label index of a document; use `document.derived(labels)` to build it once
    per version."""
    definitions: defaultdict[int, list[ast.LabelDef]] = defaultdict(list)
    jumps: defaultdict[int, list[ast.LabelRef]] = defaultdict(list)
    for number in range(1, document.program_lines() + 1):
        line = document.line(number)
        if line.label is not None and line.label.number is not None:
            definitions[line.label.number].append(line.label)
        for statement in line.statements:
            if isinstance(statement, ast.Goto | ast.CondJump):
                target = statement.target
                if target.number is not None:
                    jumps[target.number].append(target)
    return Labels(dict(definitions), dict(jumps))


def label_number(token: Token | None) -> int | None:
    """The label a token names, if it is a label definition or a jump."""
    if isinstance(token, ast.LabelDef | ast.LabelRef):
        return token.number
    return None
