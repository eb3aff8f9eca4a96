"""Hover: what the token under the cursor means, from the built-in table (the paper's
Tables 2 and 3), the label index and the constant's value."""

from __future__ import annotations

from lsprotocol import types

from rl1.compiler.frontend import ast
from rl1.vm.language import (
    BUILTINS,
    HANDLER_LABELS,
    RESERVED_VARIABLES,
    VARIABLES,
    Builtin,
    Form,
    writers_of,
)

from .document import Document
from .index import labels, token_at, token_span
from .positions import Columns

HANDLER_EVENTS = {
    96: "a lost line during `(MOV)` in tracing mode 3 (the motion continues)",
    97: "a lost line during `(MVI)` in tracing mode 3 (the move continues in the background)",
    98: "a lost line during `(MOV)` in tracing mode 2 (the vehicle is stopped)",
    99: "a lost line during `(MVI)` in tracing mode 2 (the move is aborted)",
}


def signature(builtin: Builtin, form: Form) -> str:
    """`(MVI l,r,cm)`, `(CAM A deg)`: a call as written, parameters by name."""
    words = [builtin.mnemonic]
    if form.selector is not None:
        words.append(form.selector)
    params = ",".join(param.name for param in form.params)
    return "(" + " ".join(words + ([params] if params else [])) + ")"


def describe_form(builtin: Builtin, form: Form) -> str:
    lines = [f"```rl1\n{signature(builtin, form)}\n```", form.summary, ""]
    for param in form.params:
        lines.append(f"- `{param.name}`: {param.meaning}, {param.low}..{param.high}")
    if form.params:
        lines.append("")
    lines.append(f"**Result:** {form.result}" if form.result else "**Result:** none")
    if form.writes:
        written = ", ".join(f"`{name}`" for name in form.writes)
        lines.append(f"\n**Writes reserved variables:** {written}")
    return "\n".join(lines)


def describe_builtin(builtin: Builtin, selector: str | None) -> str:
    heading = f"**{builtin.mnemonic}**: {builtin.name} ({builtin.group})"
    waits = ("waits: takes device time before the next statement runs" if builtin.waits
             else "returns at once")
    form = builtin.form(selector) if builtin.has_selector else builtin.forms[0]
    forms = [form] if form is not None else list(builtin.forms)
    body = "\n\n---\n\n".join(describe_form(builtin, f) for f in forms)
    return f"{heading}; {waits}\n\n{body}"


def describe_variable(name: str) -> str:
    index = VARIABLES.index(name) if name in VARIABLES else None
    lines = [f"**variable `{name}`**: 16-bit signed, 0 at start"
             + (f" (index {index})" if index is not None else "")]
    if name in RESERVED_VARIABLES:
        writers = [f"`{signature(builtin, form)}`" for builtin, form in writers_of(name)]
        lines.append("Reserved: written by " + " and ".join(writers) + "."
                     if writers else "Reserved for the sensing functions.")
    else:
        lines.append("Not reserved: only the program writes it.")
    return "\n\n".join(lines)


def describe_constant(constant: ast.Const) -> str:
    pattern = constant.value & 0xFFFF
    signed = pattern - 0x10000 if pattern >= 0x8000 else pattern
    if not constant.hex and not -0x8000 <= constant.value <= 0x7FFF:
        return (f"**constant `{constant.text}`**: does not fit in 16 bits "
                "(decimal constants lie in -32768..32767)")
    return (f"**constant `{constant.text}`**\n\n"
            f"decimal {signed} · hex ${pattern:04X} · 16-bit value {signed}"
            + (f" (unsigned {pattern})" if signed < 0 else ""))


def describe_label(document: Document, number: int) -> str:
    index = document.derived(labels)
    definitions = index.definitions.get(number, [])
    jumps = index.jumps.get(number, [])
    lines = [f"**label `:{number:02d}`**"]
    if number in HANDLER_LABELS:
        lines.append(f"Tracing handler: the device jumps here on {HANDLER_EVENTS[number]}.")
    if not definitions:
        lines.append("Not defined in this program.")
    elif len(definitions) == 1:
        lines.append(f"Defined on line {definitions[0].span.line}.")
    else:
        where = ", ".join(str(d.span.line) for d in definitions)
        lines.append(f"Defined {len(definitions)} times, on lines {where}.")
    if jumps:
        sources = sorted({jump.span.line for jump in jumps})
        lines.append("Jumped to from line" + ("s " if len(sources) > 1 else " ")
                     + ", ".join(map(str, sources)) + ".")
    else:
        lines.append("No line jumps here.")
    return "\n\n".join(lines)


def hover(document: Document, position: types.Position, columns: Columns) -> types.Hover | None:
    number, column = document.locate(position, columns)
    if number > document.program_lines():
        return None
    token = token_at(document.line(number), column)
    if token is None:
        return None
    text: str | None = None
    if isinstance(token, ast.Call):
        builtin = BUILTINS.get(token.mnemonic.upper())
        selector = token.args[0] if token.args else None
        if builtin is not None:
            text = describe_builtin(
                builtin, selector.letter.upper() if isinstance(selector, ast.Selector) else None)
    elif isinstance(token, ast.Selector):
        text = _describe_selector(document.line(number), token)
    elif isinstance(token, ast.Var):
        text = describe_variable(token.name)
    elif isinstance(token, ast.Const):
        text = describe_constant(token)
    elif token.number is not None:
        text = describe_label(document, token.number)
    if text is None:
        return None
    return types.Hover(
        contents=types.MarkupContent(kind=types.MarkupKind.Markdown, value=text),
        range=document.range_of(token_span(token), columns),
    )


def _describe_selector(line: ast.Line, selector: ast.Selector) -> str | None:
    call = next(
        (node for node in ast.walk(line) if isinstance(node, ast.Call) and selector in node.args),
        None,
    )
    builtin = BUILTINS.get(call.mnemonic.upper()) if call is not None else None
    if builtin is None:
        return None
    form = builtin.form(selector.letter.upper())
    if form is None:
        letters = ", ".join(f.selector or "" for f in builtin.forms)
        return f"`{selector.letter}` is not a form of `({builtin.mnemonic} ...)`: use {letters}"
    return describe_form(builtin, form)
