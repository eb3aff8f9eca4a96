"""The parser: RL/I text to the AST, one line at a time.

Each line is parsed alone, so a syntax error on one line never hides the errors on the
others, and the language server can re-parse only the lines an edit touches.

The LALR(1) tables (lalr_tables.py, lark's analysis of grammar.lark) look only at the
kinds of a line's tokens, so what the automaton does with a line (every shift and
reduction, or the token at which it gives up) depends on those kinds alone. The parser
runs the automaton once for each sequence of kinds it meets and keeps the outcome as a
*plan*: either a builder that makes the AST of any line with those kinds from its
lexemes (builders.py), or the place and the expectation of the syntax error. A program
has far fewer kinds of line than lines, so most lines are parsed by a cache look-up and
a call.
"""

from __future__ import annotations

import functools
import unicodedata
from typing import Any, NamedTuple

from rl1.vm.language import BUILTINS

from . import ast
from .builders import ACTIONS, Builder, Child, ParsedLine, label_def
from .characters import UNSEEN_ALONE, code_point
from .collector import collector_paused
from .diagnostics import Diagnostic, Edit, Fix, Severity
from .lalr_tables import ACTIONS as TABLE
from .lalr_tables import RULES, START
from .scanner import Kinds, Lexeme, scan
from .source import iter_lines

# What each terminal is called in "expected ..." messages.
TERMINAL_NAMES = {
    "VAR": "a variable", "NUMBER": "a number", "HEX": "a `$` hex constant",
    "MNEMONIC": "a function name", "LABELREF": "a jump target `#NN`", "LABEL": "a label",
    "EQUAL": "`=`", "INCDEC": "`++` or `--`", "QMARK": "`?`", "LPAR": "`(`", "RPAR": "`)`",
    "OPERATOR": "an operator", "LESS": "`<`", "MORE": "`>`", "_SEMI": "`;`", "_COMMA": "`,`",
    "$END": "the end of the line",
}

MAX_LINE_LENGTH = 20_000
"""The longest code part of a line that is read (E0106 beyond): a line's memory grows
with its tokens, so a megabyte line is refused before any is made."""

_LONGEST_CACHED_PLAN = 64
"""Lines of more tokens than this are planned afresh each time: they are rare, and one
huge line's plan could fill the cache."""


class Rejection(NamedTuple):
    """The outcome of a line the grammar rejects: the index of the token the automaton
    could not take (None: the end of the line) and the terminals it expected there."""

    token: int | None
    expected: frozenset[str]


Plan = Builder[ParsedLine] | Rejection
"""What a line of some kinds parses to: the builder of its AST, or why it is rejected."""


def make_plan(kinds: Kinds) -> Plan:
    """Run the LALR automaton over `kinds`, building with the rules' actions."""
    states = [START]
    values: list[Any] = []  # a token's index, a builder, or a list to splice
    for index in range(len(kinds) + 1):
        kind = kinds[index] if index < len(kinds) else "$END"
        while True:
            action = TABLE[states[-1]].get(kind)
            if action is None:
                expected = frozenset(name for name in TABLE[states[-1]] if name.isupper())
                return Rejection(index if index < len(kinds) else None, expected)
            if action >= 0:
                states.append(action)
                values.append(index)
                break
            name, expansion, inline_single = RULES[-1 - action]
            size = len(expansion)
            popped = values[len(values) - size:]
            del states[len(states) - size:]
            del values[len(values) - size:]
            value = _reduce(kinds, name, expansion, inline_single, popped)
            if name == "line" and len(states) == 1:
                return value  # type: ignore[no-any-return]
            values.append(value)
            states.append(TABLE[states[-1]][name])
    raise AssertionError("the LALR tables accept no line without reducing `line`")


def _reduce(kinds: Kinds, name: str, expansion: tuple[str, ...], inline_single: bool,
            popped: list[Any]) -> Any:
    """What lark's tree builder would make of a reduction: `_TERMINALS` are dropped,
    `_rules` spliced into their parent, `?rules` with one child replaced by it."""
    children: list[Child] = []
    for symbol, value in zip(expansion, popped, strict=True):
        if symbol[0] != "_":
            children.append(value)
        elif symbol.isupper():
            continue
        elif children:
            children.extend(value)
        else:
            # Adopt the list rather than copy it: each list is spliced into one parent
            # only, and copying it at every step of a left-recursive rule (`A=1+1+...`,
            # `A=1;A=1;...`) would make a long line's parse time grow with its square.
            children = value
    if name[0] == "_":
        return children
    if inline_single and len(children) == 1:
        return children[0]
    return ACTIONS[name](kinds, children)


_cached_plan = functools.lru_cache(maxsize=4096)(make_plan)


def _plan(kinds: Kinds) -> Plan:
    return _cached_plan(kinds) if len(kinds) <= _LONGEST_CACHED_PLAN else make_plan(kinds)


def _syntax_error(row: ast.Row, code: str, kinds: Kinds, lexemes: list[Lexeme],
                  rejection: Rejection) -> Diagnostic:
    if rejection.token is None:
        column = len(code.rstrip()) + 1
        span = ast.Span(row, column, row, column + 1)
        kind, text = "$END", ""
    else:
        kind = kinds[rejection.token]
        text, start = lexemes[rejection.token]
        span = ast.Span(row, start + 1, row, start + 1 + max(len(text), 1))
    if kind == "BAD":
        return _bad_character(span, text)
    if kind == "WORD":
        return _misused_word(row, span, kinds, lexemes, rejection.token)
    if kind == "BADHEX":
        return Diagnostic(
            "E0105", Severity.ERROR, f"`{_excerpt(text)}` is not a 16-bit hex constant", span,
            help="write `$` and one to four hex digits 0-9, A-F, e.g. `$FF` or `$AA55`",
        )
    if kind == "LABEL":
        return Diagnostic(
            "E0104", Severity.ERROR,
            f"the label `{_excerpt(text)}` is not at the start of its line",
            span, help="a label `:NN` may only start a line: move it to a line of its own",
        )
    found = "the end of the line" if kind == "$END" else f"`{_excerpt(text)}`"
    help_text, fixes = _syntax_help(row, kinds, lexemes, rejection)
    return Diagnostic("E0101", Severity.ERROR, _expected(rejection.expected, found), span,
                      help=help_text, fixes=fixes)


@functools.lru_cache(maxsize=1024)
def _expected(expected: frozenset[str], found: str) -> str:
    """The message of an E0101, one string for the many lines that share it: a
    diagnostic is kept until it is reported, and a source of a broken line on end would
    otherwise hold its message's text once a line."""
    names = sorted({TERMINAL_NAMES.get(name, name) for name in expected})
    return f"expected {_either(names)}, found {found}"


def _either(names: list[str]) -> str:
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " or " + names[-1]


# The tokens a statement can start with, for "two statements without a `;`".
_STARTS_STATEMENT = frozenset({"VAR", "LPAR", "LABELREF", "QMARK"})


def _syntax_help(row: ast.Row, kinds: Kinds, lexemes: list[Lexeme],
                 rejection: Rejection) -> tuple[str | None, tuple[Fix, ...]]:
    """The help of an E0101, and its fix when the intent is plain."""
    index, expected = rejection.token, rejection.expected
    found = lexemes[index][0] if index is not None else ""
    if found == "-" and "_COMMA" in expected and index is not None:
        # `(MOV 3 -3)`: after an argument, ` -3` scans as a subtraction (3.2).
        fixes: tuple[Fix, ...] = ()
        if index + 1 < len(kinds) and kinds[index + 1] == "NUMBER" \
                and lexemes[index + 1][1] == lexemes[index][1] + 1:
            fixes = (Fix("write a comma before the negative number",
                         (_between(row, lexemes, index, ","),), safe=True),)
        return ("separate a negative argument with a comma, as in `(MOV 3,-3)`: after an "
                "argument, ` -3` reads as a subtraction, which a call's arguments cannot "
                "hold"), fixes
    if "VAR" in expected and "NUMBER" in expected and found.startswith("-"):
        return "there is no unary minus on a variable: write `0-V` for the negative of V", ()
    if "_SEMI" in expected and index is not None and kinds[index] in _STARTS_STATEMENT:
        return ("statements on one line are separated by `;`, as in `A=1; B=2`",
                (Fix("separate the statements with `;`",
                     (_between(row, lexemes, index, "; "),), safe=True),))
    if expected == {"RPAR"} or ("RPAR" in expected and "_COMMA" in expected):
        return "close the call with `)`", ()
    if found == "=" and "VAR" in expected:  # where a statement or an operand starts
        return ("an assignment starts with the variable it sets, as in `A=3`"
                if "LABELREF" in expected else
                "`=` is written once, as in `A=3`; a comparison is a jump, as in `?A=#10`"), ()
    if expected == {"LABELREF"}:  # not only among a statement's starts
        return "a jump target is `#` and two digits, e.g. `#10`", ()
    return None, ()


def _between(row: ast.Row, lexemes: list[Lexeme], index: int, text: str) -> Edit:
    """Replace what lies between token `index` and the one before it with `text`."""
    before, start = lexemes[index - 1]
    end = start + len(before)
    return Edit(ast.Span(row, end + 1, row, lexemes[index][1] + 1), text)


def _bad_character(span: ast.Span, character: str) -> Diagnostic:
    ascii_form = unicodedata.normalize("NFKC", character)
    if ascii_form != character and ascii_form.isascii() and ascii_form.strip():
        help_text = f"this is a full-width character: type the ASCII `{ascii_form}` instead"
    elif character == "\u3000":
        help_text = "this is a full-width space: type an ASCII space instead"
    elif character in "*/%":
        help_text = ("RL/I has no `*`, `/` or `%`: its operators are `+ - & | ^ < >`, where "
                     "`<` and `>` shift, so `B<1` is B times 2 and `B>1` is B halved")
    elif character.isascii() and character.isprintable():
        help_text = (f"`{character}` has no meaning in RL/I code (its operators are "
                     "`+ - & | ^ < >`); a comment starts with `'`")
    elif character.isascii():
        help_text = "a control character has no place in RL/I code: delete it"
    else:
        help_text = "RL/I code is ASCII; text in any script may follow `'` as a comment"
    code, name = code_point(character), unicodedata.name(character, "")
    if unicodedata.category(character) in UNSEEN_ALONE:  # quoted: `` or ` `
        shown = f"{code} ({name})" if name else code
    else:
        shown = f"`{character}` ({name or code})"
    return Diagnostic("E0102", Severity.ERROR, f"unexpected character {shown}", span,
                      help=help_text)


def _excerpt(text: str, limit: int = 24) -> str:
    """Token text short enough to quote in a message (the span still marks all of it)."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


# Words of other languages' jumps and conditions, and what RL/I writes instead.
_JUMP_WORDS = frozenset({"GOTO", "GO", "JMP", "JUMP", "JP", "GOSUB"})
_CONDITION_WORDS = frozenset({"IF", "THEN", "ELSE"})


def _misused_word(row: ast.Row, span: ast.Span, kinds: Kinds, lexemes: list[Lexeme],
                  index: int | None) -> Diagnostic:
    word = lexemes[index][0] if index is not None else ""
    upper = word.upper()
    if upper in BUILTINS:
        return Diagnostic(
            "E0103", Severity.ERROR,
            f"`{word}` is a built-in function, which is called in parentheses", span,
            help=f"write `({upper} ...)`",
        )
    message = f"`{_excerpt(word)}` is not a variable: variable names are one letter"
    if upper in _JUMP_WORDS and index is not None:
        return Diagnostic("E0103", Severity.ERROR, message, span,
                          help="RL/I jumps with `#` and two digits: `#10` goes on at the "
                               "line that starts with the label `:10`",
                          fixes=_jump_fix(row, kinds, lexemes, index))
    if upper in _CONDITION_WORDS:
        return Diagnostic("E0103", Severity.ERROR, message, span,
                          help="RL/I's only condition is the conditional jump: `?A=#10` "
                               "jumps to `:10` when A is 0, `?A>#10` when A is positive, "
                               "`?A<#10` when A is negative")
    return Diagnostic(
        "E0103", Severity.ERROR, message,
        span, help="use one of A-Z, a-z or @; built-in functions are written `(NAME ...)`",
    )


def _jump_fix(row: ast.Row, kinds: Kinds, lexemes: list[Lexeme], index: int
              ) -> tuple[Fix, ...]:
    """`GOTO 10` -> `#10`, when a label's number follows the word."""
    if index + 1 >= len(kinds) or kinds[index + 1] != "NUMBER":
        return ()
    number, start = lexemes[index + 1]
    if not number.isdigit() or int(number) > 99:
        return ()
    target = f"#{int(number):02d}"
    span = ast.Span(row, lexemes[index][1] + 1, row, start + len(number) + 1)
    return (Fix(f"write `{target}`", (Edit(span, target),)),)


def parse_line(text: str, line: int | ast.Row) -> tuple[ast.Line, list[Diagnostic]]:
    """Parse one line of source (no line end) as line `line`: its number, or the row
    that will hold its number as it moves (every span on the line refers to it)."""
    row = line if isinstance(line, ast.Row) else ast.Row(line)
    code, quote, comment_text = text.partition("'")
    comment = None
    if quote:
        comment = ast.Comment(ast.Span(row, len(code) + 1, row, len(text) + 1),
                              comment_text)
    span = ast.Span(row, 1, row, len(text) + 1)
    if len(code) > MAX_LINE_LENGTH:
        return ast.Line(span, None, (), comment, ok=False), [_too_long(row, code)]
    kinds, lexemes = scan(code)
    if not kinds:
        return ast.Line(span, None, (), comment), []
    plan = _plan(kinds)
    if isinstance(plan, Rejection):
        # A broken line keeps its label, so that jumps to it still resolve and the
        # checker need not assume the worst about it.
        label = label_def(lexemes, row) if kinds[0] == "LABEL" else None
        return ast.Line(span, label, (), comment, ok=False), [
            _syntax_error(row, code, kinds, lexemes, plan)
        ]
    label, statements = plan(lexemes, row)
    return ast.Line(span, label, statements, comment), []


def _too_long(row: ast.Row, code: str) -> Diagnostic:
    return Diagnostic(
        "E0106", Severity.ERROR,
        f"this line has {len(code):,} characters of code; RL/I reads lines of up to "
        f"{MAX_LINE_LENGTH:,}", ast.Span(row, 1, row, len(code) + 1),
        help="put the statements on lines of their own (a comment after `'` may be as "
             "long as you like)",
    )


def parse_program(text: str) -> tuple[ast.Program, list[Diagnostic]]:
    """Parse a whole source text; the diagnostics are the syntax errors of every line."""
    lines: list[ast.Line] = []
    diagnostics: list[Diagnostic] = []
    with collector_paused():
        for number, line_text in enumerate(iter_lines(text), start=1):
            line, problems = parse_line(line_text, number)
            lines.append(line)
            if problems:
                diagnostics.extend(problems)
    end = lines[-1].span if lines else ast.Span(1, 1, 1, 1)
    return ast.Program(ast.Span(1, 1, end.end_line, end.end_column), tuple(lines)), diagnostics
