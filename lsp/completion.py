"""Completion and signature help, both read from the text before the cursor: completion
must work on a line that does not parse yet, which is most lines being typed."""

from __future__ import annotations

import re

from lsprotocol import types

from rl1.vm.language import BUILTINS, RESERVED_VARIABLES, VARIABLES, Builtin, Form, writers_of

from .document import Document
from .hover import describe_builtin, describe_form, signature
from .index import labels
from .positions import Columns

TRIGGER_CHARACTERS = ["(", "#", " "]
SIGNATURE_TRIGGERS = ["(", ",", " "]

_LABEL_PREFIX = re.compile(r"#(\d*)$")
_SELECTOR_PREFIX = re.compile(r"\(\s*([A-Za-z]{3})\s+([A-Za-z]?)$")
_MNEMONIC_PREFIX = re.compile(r"\(\s*([A-Za-z]*)$")
_VARIABLE_PREFIX = re.compile(r"(?:^|[\s;=+\-&|^<>?,])([A-Za-z@]?)$")
_OPEN_CALL = re.compile(r"\(\s*([A-Za-z]+)([^()]*)$")


def _code_before(document: Document, position: types.Position,
                 columns: Columns) -> tuple[int, int, str, str] | None:
    """(line, column, code before the cursor, text after it); None inside a comment."""
    number, column = document.locate(position, columns)
    text = document.line_text(number)
    before = text[: column - 1]
    if "'" in before:
        return None
    return number, column, before, text[column - 1 :]


def _replace(number: int, text: str, start: int, end: int, columns: Columns) -> types.Range:
    """The client range of 1-based code-point columns [start, end) of a line."""
    return types.Range(
        start=types.Position(number - 1, columns.to_client(text, start - 1)),
        end=types.Position(number - 1, columns.to_client(text, end - 1)),
    )


def _snippet(words: list[str], form: Form, close: bool) -> str:
    """`MVI ${1:l},${2:r},${3:cm})`: tab stops named after the parameters."""
    params = ",".join(f"${{{i}:{p.name}}}" for i, p in enumerate(form.params, start=1))
    return " ".join(words + ([params] if params else [])) + (")" if close else "")


def _documentation(text: str, markdown: bool) -> types.MarkupContent | str:
    return types.MarkupContent(kind=types.MarkupKind.Markdown, value=text) if markdown else text


def _mnemonic_items(builtin: Builtin, snippets: bool, markdown: bool, close: bool,
                    edit_range: types.Range) -> list[types.CompletionItem]:
    items = []
    for form in builtin.forms:
        words = [builtin.mnemonic] + ([form.selector] if form.selector else [])
        label = " ".join(words)
        text = _snippet(words, form, close) if snippets else label
        items.append(types.CompletionItem(
            label=label,
            kind=types.CompletionItemKind.Function,
            detail=signature(builtin, form),
            documentation=_documentation(describe_builtin(builtin, form.selector), markdown),
            filter_text=label,
            text_edit=types.TextEdit(range=edit_range, new_text=text),
            insert_text_format=(types.InsertTextFormat.Snippet if snippets
                                else types.InsertTextFormat.PlainText),
        ))
    return items


def _variable_detail(name: str) -> str:
    if name not in RESERVED_VARIABLES:
        return "variable"
    writers = [signature(builtin, form) for builtin, form in writers_of(name)]
    return "reserved, written by " + " and ".join(writers) if writers else "reserved"


def complete(document: Document, position: types.Position, columns: Columns,
             snippets: bool, markdown: bool) -> list[types.CompletionItem]:
    """Labels after `#`, selectors after `(CAM ` and `(ULT `, mnemonics after `(`,
    variables where an operand or a statement may start."""
    context = _code_before(document, position, columns)
    if context is None:
        return []
    number, column, before, after = context
    text = document.line_text(number)
    close = not after.lstrip().startswith(")")

    if found := _LABEL_PREFIX.search(before):
        edit_range = _replace(number, text, column - len(found.group(1)), column, columns)
        index = document.derived(labels)
        return [
            types.CompletionItem(
                label=f"{label:02d}",
                kind=types.CompletionItemKind.Reference,
                detail=f"line {index.definitions[label][0].span.line}",
                text_edit=types.TextEdit(range=edit_range, new_text=f"{label:02d}"),
            )
            for label in index.defined()
        ]
    if (found := _SELECTOR_PREFIX.search(before)) and (
            builtin := BUILTINS.get(found.group(1).upper())) and builtin.has_selector:
        edit_range = _replace(number, text, column - len(found.group(2)), column, columns)
        return [
            types.CompletionItem(
                label=form.selector or "",
                kind=types.CompletionItemKind.EnumMember,
                detail=form.summary,
                documentation=_documentation(describe_form(builtin, form), markdown),
                text_edit=types.TextEdit(
                    range=edit_range,
                    new_text=_snippet([form.selector or ""], form, close) if snippets
                    else form.selector or ""),
                insert_text_format=(types.InsertTextFormat.Snippet if snippets
                                    else types.InsertTextFormat.PlainText),
            )
            for form in builtin.forms
        ]
    if found := _MNEMONIC_PREFIX.search(before):
        edit_range = _replace(number, text, column - len(found.group(1)), column, columns)
        return [item for builtin in BUILTINS.values()
                for item in _mnemonic_items(builtin, snippets, markdown, close, edit_range)]
    if found := _VARIABLE_PREFIX.search(before):
        edit_range = _replace(number, text, column - len(found.group(1)), column, columns)
        return [
            types.CompletionItem(
                label=name, kind=types.CompletionItemKind.Variable,
                detail=_variable_detail(name),
                text_edit=types.TextEdit(range=edit_range, new_text=name),
            )
            for name in VARIABLES
        ]
    return []


def _signature_information(builtin: Builtin, form: Form) -> types.SignatureInformation:
    """`(CAM A deg)`: the selector, when there is one, counts as the first parameter."""
    label = "(" + builtin.mnemonic
    parameters = []
    names = ([(form.selector, f"selects: {form.summary}")] if form.selector else []) + [
        (param.name, f"{param.meaning}, {param.low}..{param.high}") for param in form.params
    ]
    for index, (name, meaning) in enumerate(names):
        label += " " if index == 0 or (form.selector and index == 1) else ","
        parameters.append(types.ParameterInformation(
            label=(len(label), len(label) + len(name)), documentation=meaning))
        label += name
    return types.SignatureInformation(
        label=label + ")",
        documentation=types.MarkupContent(kind=types.MarkupKind.Markdown, value=form.summary),
        parameters=parameters,
    )


def signature_help(document: Document, position: types.Position,
                   columns: Columns) -> types.SignatureHelp | None:
    context = _code_before(document, position, columns)
    if context is None:
        return None
    found = _OPEN_CALL.search(context[2])
    builtin = BUILTINS.get(found.group(1).upper()) if found else None
    if found is None or builtin is None:
        return None
    typed = found.group(2)
    args = re.findall(r"[^\s,]+", typed)
    if typed and typed[0] not in " \t,":
        return None  # a word longer than a mnemonic: "(MVIX"
    active = len(args) if typed and typed[-1] in " \t," else max(len(args) - 1, 0)
    forms = list(builtin.forms)
    chosen = 0
    if builtin.has_selector and args:
        chosen = next((i for i, f in enumerate(forms) if f.selector == args[0].upper()), 0)
    return types.SignatureHelp(
        signatures=[_signature_information(builtin, form) for form in forms],
        active_signature=chosen,
        active_parameter=active,
    )
