"""Moving around a program: definition, references, highlights, renaming a label, the
outline of labels and the folding of sections and comment blocks."""

from __future__ import annotations

import re
from collections import defaultdict

from lsprotocol import types
from pygls.exceptions import JsonRpcException

from rl1.compiler.frontend import ast
from rl1.vm.language import HANDLER_LABELS

from .document import Document
from .index import Token, label_number, labels, token_at, token_span
from .positions import Columns

_NEW_LABEL = re.compile(r"[:#]?(\d+)")


class RequestFailed(JsonRpcException):
    """LSP's RequestFailed: a well-formed request the server refuses, with a message
    for the user."""

    CODE = -32803
    MESSAGE = "Request failed"


def _token(document: Document, position: types.Position, columns: Columns) -> Token | None:
    number, column = document.locate(position, columns)
    if number > document.program_lines():
        return None
    return token_at(document.line(number), column)


def _location(document: Document, span: ast.Span, columns: Columns) -> types.Location:
    return types.Location(document.uri, document.range_of(span, columns))


# Variables --------------------------------------------------------------------------


def _operand_vars(operand: ast.Operand, into: list[tuple[ast.Var, bool]]) -> None:
    if isinstance(operand, ast.Var):
        into.append((operand, False))
    elif isinstance(operand, ast.Call):
        into.extend((arg, False) for arg in operand.args if isinstance(arg, ast.Var))


def variables_of(line: ast.Line) -> list[tuple[ast.Var, bool]]:
    """Each variable of a line, with True where the statement writes it."""
    found: list[tuple[ast.Var, bool]] = []
    for statement in line.statements:
        if isinstance(statement, ast.Assign):
            found.append((statement.target, True))
            _operand_vars(statement.first, found)
            for step in statement.rest:
                _operand_vars(step.operand, found)
        elif isinstance(statement, ast.IncDec):
            found.append((statement.target, True))
        elif isinstance(statement, ast.CondJump):
            found.append((statement.var, False))
        elif isinstance(statement, ast.CallStmt):
            _operand_vars(statement.call, found)
    return found


def variables(document: Document) -> dict[str, list[tuple[ast.Var, bool]]]:
    """Every use of every variable; build it once per version with `document.derived`."""
    index: defaultdict[str, list[tuple[ast.Var, bool]]] = defaultdict(list)
    for number in range(1, document.program_lines() + 1):
        for var, writes in variables_of(document.line(number)):
            index[var.name].append((var, writes))
    return dict(index)


# Definition, references, highlights -------------------------------------------------


def definition(document: Document, position: types.Position,
               columns: Columns) -> list[types.Location] | None:
    number = label_number(_token(document, position, columns))
    if number is None:
        return None
    found = document.derived(labels).definitions.get(number, [])
    return [_location(document, d.span, columns) for d in found] or None


def _occurrences(document: Document, token: Token | None,
                 include_definition: bool) -> list[tuple[ast.Span, bool]]:
    """The spans naming the same label or variable as `token`, True for definitions
    and writes."""
    if isinstance(token, ast.Var):
        return [(var.span, writes) for var, writes
                in document.derived(variables).get(token.name, [])]
    number = label_number(token)
    if number is None:
        return []
    index = document.derived(labels)
    found = [(d.span, True) for d in index.definitions.get(number, [])]
    if not include_definition:
        found = []
    found += [(jump.span, False) for jump in index.jumps.get(number, [])]
    return sorted(found, key=lambda item: (item[0].line, item[0].column))


def references(document: Document, position: types.Position, columns: Columns,
               include_declaration: bool) -> list[types.Location]:
    token = _token(document, position, columns)
    return [_location(document, span, columns)
            for span, _ in _occurrences(document, token, include_declaration)]


def highlights(document: Document, position: types.Position,
               columns: Columns) -> list[types.DocumentHighlight]:
    token = _token(document, position, columns)
    return [
        types.DocumentHighlight(
            range=document.range_of(span, columns),
            kind=types.DocumentHighlightKind.Write if writes else types.DocumentHighlightKind.Read,
        )
        for span, writes in _occurrences(document, token, include_definition=True)
    ]


# Rename -----------------------------------------------------------------------------


def _renamable(document: Document, position: types.Position,
               columns: Columns) -> tuple[Token, int]:
    token = _token(document, position, columns)
    number = label_number(token)
    if token is None or number is None:
        raise RequestFailed("only labels can be renamed: put the cursor on a label "
                            "`:NN` or a jump `#NN`")
    if number in HANDLER_LABELS:
        raise RequestFailed(
            f"`:{number}` is a tracing handler label: the device jumps to it by its number "
            "when the guidance line is lost, so it cannot be renumbered")
    return token, number


def prepare_rename(document: Document, position: types.Position,
                   columns: Columns) -> types.PrepareRenameResult:
    token, number = _renamable(document, position, columns)
    return types.PrepareRenamePlaceholder(
        range=document.range_of(token_span(token), columns), placeholder=f"{number:02d}")


def rename(document: Document, position: types.Position, columns: Columns,
           new_name: str) -> types.WorkspaceEdit:
    _, number = _renamable(document, position, columns)
    wanted = _NEW_LABEL.fullmatch(new_name.strip())
    if wanted is None or len(wanted.group(1)) != 2:
        raise RequestFailed(
            f"`{new_name}` is not a label number: labels are two digits, :00 to :99 "
            "(write `20`, `:20` or `#20`)")
    target = int(wanted.group(1))
    index = document.derived(labels)
    if target in HANDLER_LABELS:
        raise RequestFailed(
            f"`:{target}` is a tracing handler label (:96-:99), which the device jumps to "
            "when the line is lost: pick a number below 96")
    if target != number and target in index.definitions:
        line = index.definitions[target][0].span.line
        raise RequestFailed(
            f"label `:{target:02d}` is already defined on line {line}: pick a number no "
            "label uses")
    edits = [
        types.TextEdit(range=document.range_of(d.span, columns), new_text=f":{target:02d}")
        for d in index.definitions.get(number, [])
    ] + [
        types.TextEdit(range=document.range_of(j.span, columns), new_text=f"#{target:02d}")
        for j in index.jumps.get(number, [])
    ]
    return types.WorkspaceEdit(changes={document.uri: edits})


# Outline and folding ----------------------------------------------------------------


def _sections(document: Document) -> list[tuple[ast.LabelDef, int]]:
    """Each label with the last line of its section (up to the next label)."""
    starts = sorted(
        (d for found in document.derived(labels).definitions.values() for d in found),
        key=lambda d: d.span.line,
    )
    if not starts:
        return []
    ends = [following.span.line - 1 for following in starts[1:]] + [document.program_lines()]
    sections = []
    for label, end in zip(starts, ends, strict=True):
        while end > label.span.line and not document.line_text(end).strip():
            end -= 1  # blank lines before the next label belong to neither
        sections.append((label, end))
    return sections


def symbols(document: Document, columns: Columns) -> list[types.DocumentSymbol]:
    result = []
    for label, end in _sections(document):
        text = document.line_text(label.span.line)
        handler = label.number in HANDLER_LABELS
        result.append(types.DocumentSymbol(
            name=label.text,
            detail=text[label.span.end_column - 1 :].strip() or None,
            kind=types.SymbolKind.Event if handler else types.SymbolKind.Namespace,
            range=types.Range(
                start=types.Position(label.span.line - 1, 0),
                end=types.Position(end - 1, columns.length(document.line_text(end))),
            ),
            selection_range=document.range_of(label.span, columns),
        ))
    return result


def folding_ranges(document: Document) -> list[types.FoldingRange]:
    ranges = [
        types.FoldingRange(start_line=label.span.line - 1, end_line=end - 1,
                           kind=types.FoldingRangeKind.Region)
        for label, end in _sections(document) if end > label.span.line
    ]
    run_start = None
    for number in range(1, document.program_lines() + 2):
        is_comment = (number <= document.program_lines()
                      and document.line_text(number).lstrip().startswith("'"))
        if is_comment and run_start is None:
            run_start = number
        elif not is_comment and run_start is not None:
            if number - 1 > run_start:
                ranges.append(types.FoldingRange(start_line=run_start - 1,
                                                 end_line=number - 2,
                                                 kind=types.FoldingRangeKind.Comment))
            run_start = None
    return ranges
