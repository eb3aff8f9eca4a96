"""The rules that look at one line alone: built-in calls and their arguments, constants,
the text of labels and jump targets, assignments to reserved variables.

The language server caches these results per line, so nothing here may look beyond the
line it is given. Lines with a syntax error are skipped: the parser has said why.
"""

from __future__ import annotations

import functools

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Edit, Fix, Severity
from rl1.vm.language import BUILTINS, RESERVED_VARIABLES, Builtin, Form, writers_of

E, W = Severity.ERROR, Severity.WARNING
INT16_LOW, INT16_HIGH = -0x8000, 0x7FFF


def check_line(line: ast.Line) -> list[Diagnostic]:
    """The per-line diagnostics of `line`, in source order."""
    if not line.ok:
        return []
    found: list[Diagnostic] = []
    if line.label is not None and line.label.number is None:
        found.append(_malformed_label(line.label.text, line.label.span, "a label", ":"))
    for statement in line.statements:
        if isinstance(statement, ast.Assign):
            if statement.target.name in RESERVED_VARIABLES:
                found.append(_reserved_target(statement.target))
            if not isinstance(statement.first, ast.Var):
                _operand(statement.first, found)
            for step in statement.rest:
                if not isinstance(step.operand, ast.Var):
                    _operand(step.operand, found)
        elif isinstance(statement, ast.IncDec):
            if statement.target.name in RESERVED_VARIABLES:
                found.append(_reserved_target(statement.target))
        elif isinstance(statement, ast.CallStmt):
            _call(statement.call, found, used_as_operand=False)
        elif statement.target.number is None:
            target = statement.target
            found.append(_malformed_label(target.text, target.span, "a jump target", "#"))
    return found


# Labels and jump targets ------------------------------------------------------------


def _malformed_label(text: str, span: ast.Span, what: str, sigil: str) -> Diagnostic:
    digits = text[1:]
    fixes: tuple[Fix, ...] = ()
    if not digits:
        help_text = f"write two digits after `{sigil}`, e.g. `{sigil}10`"
    elif len(digits.lstrip("0")) <= 2:
        fixed = f"{sigil}{int(digits):02d}"
        help_text = f"write `{fixed}`"
        fixes = (Fix(f"write `{fixed}`", (Edit(span, fixed),), safe=True),)
    else:
        named = "labels" if sigil == ":" else "jump targets"
        help_text = f"{named} run from `{sigil}00` to `{sigil}99`"
    code = "E0201" if sigil == ":" else "E0202"
    return Diagnostic(code, E, f"`{text}` is not {what}: it needs exactly two digits after "
                      f"`{sigil}`", span, help=help_text, fixes=fixes)


# Assignments ------------------------------------------------------------------------


def _reserved_target(target: ast.Var) -> Diagnostic:
    return Diagnostic(
        "W0402", W, _overwritten(target.name), target.span,
        help="keep your own values in A-Z, a-r or @; s-z belong to the sensing calls",
    )


@functools.cache
def _overwritten(name: str) -> str:
    """The message of a W0402 on `name`, made once a name: a source writing `t` on each
    line spent a tenth of `rl1c check`'s time finding the built-ins that write it."""
    writers = " and ".join(f"`({builtin.mnemonic})`" for builtin, _ in writers_of(name))
    return f"`{name}` is a reserved variable: {writers} overwrites it"


def _operand(operand: ast.Const | ast.Call, found: list[Diagnostic]) -> None:
    if isinstance(operand, ast.Const):
        if not INT16_LOW <= operand.value <= INT16_HIGH:
            found.append(_too_wide(operand))
    elif isinstance(operand, ast.Call):
        _call(operand, found, used_as_operand=True)


def _too_wide(const: ast.Const) -> Diagnostic:
    fixes: tuple[Fix, ...] = ()
    if 0x8000 <= const.value <= 0xFFFF:
        pattern = f"${const.value:04X}"
        help_text = f"for the 16-bit pattern of {const.value}, write `{pattern}`"
        fixes = (Fix(f"write `{pattern}`", (Edit(const.span, pattern),)),)
    else:
        help_text = "values are 16-bit: use a constant in -32768..32767"
    return Diagnostic("E0507", E, f"`{const.text}` does not fit in 16 bits: decimal constants "
                      "lie in -32768..32767", const.span, help=help_text, fixes=fixes)


# Calls ------------------------------------------------------------------------------


def _call(call: ast.Call, found: list[Diagnostic], used_as_operand: bool) -> None:
    name = call.mnemonic.upper()
    builtin = BUILTINS.get(name)
    if builtin is None:
        found.append(_unknown_function(call))
        _wide_constants(call.args, found)
        return
    if call.mnemonic != name:
        found.append(_lower_case(call.mnemonic, call.mnemonic_span, "function name"))
    values = call.args
    form = builtin.forms[0]
    if builtin.has_selector:
        selector = values[0] if values else None
        if not isinstance(selector, ast.Selector):
            found.append(_selector_expected(call, builtin, selector))
            _wide_constants(values, found)
            return
        if selector.letter != selector.letter.upper():
            found.append(_lower_case(selector.letter, selector.span, "selector"))
        selected = builtin.form(selector.letter.upper())
        values = values[1:]
        if selected is None:
            found.append(_unknown_selector(builtin, selector))
            _wide_constants(values, found)
            return
        form = selected
    if used_as_operand and not form.returns_value:
        found.append(_no_result(call, builtin, form))
    _arguments(call, builtin, form, values, found)


def _arguments(call: ast.Call, builtin: Builtin, form: Form, values: tuple[ast.Arg, ...],
               found: list[Diagnostic]) -> None:
    params = form.params
    for param, arg in zip(params, values, strict=False):
        if isinstance(arg, ast.Selector):
            found.append(Diagnostic(
                "E0504", E, f"expected a value for {param.name}, found the letter `{arg.letter}`",
                arg.span, help=f"`{signature(builtin, form)}`: {_describe(form)}",
            ))
        elif isinstance(arg, ast.Const):
            if not INT16_LOW <= arg.value <= INT16_HIGH:
                found.append(_too_wide(arg))
            elif not param.low <= arg.value <= param.high:
                value = f" ({arg.value})" if arg.hex else ""
                found.append(Diagnostic(
                    "E0506", E, f"`{arg.text}`{value} is out of range for {param.name} "
                    f"({param.meaning}): {param.low}..{param.high}", arg.span,
                    help=f"`{signature(builtin, form)}`: {_describe(form)}",
                ))
    if len(values) != len(params):
        found.append(_arity(call, builtin, form, values))
    _wide_constants(values[len(params):], found)


def _arity(call: ast.Call, builtin: Builtin, form: Form, values: tuple[ast.Arg, ...]) -> Diagnostic:
    expected = len(form.params)
    counted = {0: "no arguments", 1: "1 argument"}.get(expected, f"{expected} arguments")
    after = " after the selector" if form.selector is not None else ""
    message = f"`{signature(builtin, form)}` takes {counted}{after}, found {len(values)}"
    help_text = (f"`{signature(builtin, form)}`: {_describe(form)}" if expected
                 else f"write `{signature(builtin, form)}`")
    if len(values) < expected:
        return Diagnostic("E0503", E, message, call.span, help=help_text)
    extra = values[expected].span.cover(values[-1].span)
    kept = values[expected - 1] if expected else (call.args[0] if form.selector else None)
    start = kept.span if kept is not None else call.mnemonic_span
    removal = start.end_to_end_of(extra)  # on the line's row, so it moves with it
    return Diagnostic("E0503", E, message, extra, help=help_text,
                      fixes=(Fix("remove the extra arguments", (Edit(removal, ""),)),))


def _wide_constants(args: tuple[ast.Arg, ...], found: list[Diagnostic]) -> None:
    for arg in args:
        if isinstance(arg, ast.Const) and not INT16_LOW <= arg.value <= INT16_HIGH:
            found.append(_too_wide(arg))


def _unknown_function(call: ast.Call) -> Diagnostic:
    import difflib  # only for a misspelt name: it costs 2 ms of every start

    name = call.mnemonic.upper()
    close = difflib.get_close_matches(name, list(BUILTINS), n=1)
    message = f"`{call.mnemonic}` is not a built-in function"
    if not close:
        return Diagnostic("E0501", E, message, call.mnemonic_span,
                          help="the built-in functions are " + ", ".join(BUILTINS))
    guess = BUILTINS[close[0]]
    return Diagnostic(
        "E0501", E, message, call.mnemonic_span,
        help=f"did you mean `{guess.mnemonic}`? {guess.forms[0].summary}",
        fixes=(Fix(f"write `{guess.mnemonic}`", (Edit(call.mnemonic_span, guess.mnemonic),)),),
    )


def _lower_case(text: str, span: ast.Span, what: str) -> Diagnostic:
    return Diagnostic(
        "W0502", W, f"the {what} `{text}` is not in upper case", span,
        help=f"built-in names and selectors are written in upper case: `{text.upper()}`",
        fixes=(Fix(f"write `{text.upper()}`", (Edit(span, text.upper()),), safe=True),),
    )


def _selector_expected(call: ast.Call, builtin: Builtin,
                       found: ast.Var | ast.Const | None) -> Diagnostic:
    letters = _either([form.selector or "" for form in builtin.forms])
    if found is None:
        return Diagnostic("E0504", E, f"`({builtin.mnemonic})` needs a selector letter: {letters}",
                          call.span, help=_forms_help(builtin))
    text = found.name if isinstance(found, ast.Var) else found.text
    return Diagnostic("E0504", E, f"expected a selector letter ({letters}), found `{text}`",
                      found.span, help=_forms_help(builtin))


def _unknown_selector(builtin: Builtin, selector: ast.Selector) -> Diagnostic:
    return Diagnostic("E0505", E,
                      f"`{selector.letter}` is not a selector of `({builtin.mnemonic} ...)`",
                      selector.span, help=_forms_help(builtin))


def _no_result(call: ast.Call, builtin: Builtin, form: Form) -> Diagnostic:
    return Diagnostic(
        "E0508", E, f"`{signature(builtin, form)}` returns no value, so it cannot be an operand",
        call.span,
        help=f"call it as a statement of its own; the calls that return a value are {_RETURNING}",
    )


def signature(builtin: Builtin, form: Form) -> str:
    """`(MOV l,r)`, `(CAM A deg)`, `(FRE)`: how a form is called."""
    head = builtin.mnemonic + (f" {form.selector}" if form.selector else "")
    params = ",".join(param.name for param in form.params)
    return f"({head} {params})" if params else f"({head})"


def _describe(form: Form) -> str:
    return "; ".join(param.describe() for param in form.params)


def _forms_help(builtin: Builtin) -> str:
    return "; ".join(f"`{signature(builtin, form)}` {form.summary[0].lower()}"
                     f"{form.summary[1:].rstrip('.')}" for form in builtin.forms)


_RETURNING = ", ".join(f"`{signature(builtin, form)}`" for builtin in BUILTINS.values()
                       for form in builtin.forms if form.returns_value)


def _either(names: list[str]) -> str:
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " or " + names[-1]
