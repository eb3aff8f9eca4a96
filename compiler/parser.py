"""The parser: RL/I text to the AST, one line at a time.

Each line is parsed alone, so a syntax error on one line never hides the errors on the
others, and the language server can re-parse only the lines an edit touches.

lark builds the LALR(1) tables and the tree-building callbacks from grammar.lark (once per
process, cached on disk between processes); `_run_lalr` runs those tables over the
scanner's tokens. That loop is lark's own shift/reduce loop minus its per-token Token
objects and per-parse set-up, which made lark's `parse()` three times slower on the
front end's hot path.
"""

from __future__ import annotations

import gc
import itertools
import tempfile
import unicodedata
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, cast

import lark
from lark.lexer import Lexer
from lark.parsers.lalr_analysis import Shift

from . import ast
from .builtins import BUILTINS
from .diagnostics import Diagnostic, Severity
from .scanner import WHITESPACE, ScanError, Token, scan
from .source import split_lines

GRAMMAR = Path(__file__).with_name("grammar.lark")

# What each terminal is called in "expected ..." messages.
TERMINAL_NAMES = {
    "VAR": "a variable", "NUMBER": "a number", "HEX": "a `$` hex constant",
    "MNEMONIC": "a function name", "LABELREF": "a jump target `#NN`", "LABEL": "a label",
    "EQUAL": "`=`", "INCDEC": "`++` or `--`", "QMARK": "`?`", "LPAR": "`(`", "RPAR": "`)`",
    "PLUS": "an operator", "MINUS": "an operator", "AMP": "an operator", "BAR": "an operator",
    "CARET": "an operator", "LESS": "`<`", "MORE": "`>`", "_SEMI": "`;`", "_COMMA": "`,`",
    "WORD": "a word", "$END": "the end of the line",
}


_HEX_DIGITS = frozenset("0123456789ABCDEFabcdef")

_ParsedLine = tuple[ast.LabelDef | None, tuple[ast.Statement, ...]]


class _ScannerLexer(Lexer):
    """Declares to lark that tokens come from scanner.py (lark never calls it)."""

    def __init__(self, lexer_conf: object) -> None:
        pass

    def lex(self, data: str) -> object:  # type: ignore[override]
        return scan(data)


class _SyntaxError(Exception):
    def __init__(self, token: Token | None, expected: set[str]) -> None:
        super().__init__("syntax error")
        self.token = token  # None at the end of the line
        self.expected = expected


class _AstBuilder(lark.Transformer):  # type: ignore[type-arg]
    """Builds AST nodes as lark reduces rules (no intermediate parse tree)."""

    def __init__(self) -> None:
        super().__init__()
        self.line_number = 1
        self.problems: list[Diagnostic] = []

    def span(self, token: Token) -> ast.Span:
        start = token.column + 1
        return ast.Span(self.line_number, start, self.line_number, start + len(token.text))

    def operand(self, item: Token | ast.Call) -> ast.Var | ast.Const | ast.Call:
        if isinstance(item, ast.Call):
            return item
        if item.type == "VAR":
            return ast.Var(self.span(item), item.text)
        return self.constant(item)

    def constant(self, token: Token) -> ast.Const:
        text = token.text
        if token.type == "NUMBER":
            return ast.Const(self.span(token), int(text), text, False)
        digits = text[1:]
        # Checked by hand: int(..., 16) would also take "0x10" and "1_0".
        value = int(digits, 16) if digits and set(digits) <= _HEX_DIGITS else -1
        if not 0 <= value <= 0xFFFF:
            self.problems.append(Diagnostic(
                "E0105", Severity.ERROR,
                f"`{_excerpt(text)}` is not a 16-bit hex constant",
                self.span(token),
                help="write `$` and one to four hex digits 0-9, A-F, e.g. `$FF` or `$AA55`",
            ))
            value = 0
        return ast.Const(self.span(token), value - 0x10000 if value >= 0x8000 else value,
                         text, True)

    def line(self, items: list[object]) -> _ParsedLine:
        label = None
        if items and isinstance(items[0], Token):
            token = items.pop(0)
            assert isinstance(token, Token)
            label = self.label_def(token)
        return label, tuple(items)  # type: ignore[arg-type]

    def label_def(self, token: Token) -> ast.LabelDef:
        digits = token.text[1:]
        return ast.LabelDef(self.span(token), token.text,
                            int(digits) if len(digits) == 2 else None)

    def assign(self, items: list[object]) -> ast.Assign:
        target_token, _, first, *steps = items
        assert isinstance(target_token, Token)
        target = ast.Var(self.span(target_token), target_token.text)
        first_operand = self.operand(first)  # type: ignore[arg-type]
        rest = tuple(step for step in steps if isinstance(step, ast.BinaryStep))
        end = rest[-1].span if rest else first_operand.span
        return ast.Assign(target.span.cover(end), target, first_operand, rest)

    def step(self, items: list[object]) -> ast.BinaryStep:
        op_token, operand_item = items
        assert isinstance(op_token, Token)
        operand = self.operand(operand_item)  # type: ignore[arg-type]
        op_span = self.span(op_token)
        return ast.BinaryStep(op_span.cover(operand.span), op_token.text,  # type: ignore[arg-type]
                              op_span, operand)

    def incdec(self, items: list[Token]) -> ast.IncDec:
        var_token, step_token = items
        target = ast.Var(self.span(var_token), var_token.text)
        return ast.IncDec(target.span.cover(self.span(step_token)), target,
                          step_token.text)  # type: ignore[arg-type]

    def label_ref(self, token: Token) -> ast.LabelRef:
        digits = token.text[1:]
        return ast.LabelRef(self.span(token), token.text, int(digits) if len(digits) == 2 else None)

    def goto(self, items: list[Token]) -> ast.Goto:
        target = self.label_ref(items[0])
        return ast.Goto(target.span, target)

    def condjump(self, items: list[Token]) -> ast.CondJump:
        qmark, var_token, relation, target_token = items
        target = self.label_ref(target_token)
        return ast.CondJump(self.span(qmark).cover(target.span),
                            ast.Var(self.span(var_token), var_token.text),
                            relation.text, target)  # type: ignore[arg-type]

    def call(self, items: list[Token]) -> ast.Call:
        lpar, mnemonic, *args, rpar = items
        builtin = BUILTINS.get(mnemonic.text.upper())
        built: list[ast.Arg] = []
        for index, arg in enumerate(args):
            if index == 0 and arg.type == "VAR" and builtin is not None and builtin.has_selector:
                built.append(ast.Selector(self.span(arg), arg.text))
            else:
                built.append(self.operand(arg))  # type: ignore[arg-type]
        return ast.Call(self.span(lpar).cover(self.span(rpar)), mnemonic.text,
                        self.span(mnemonic), tuple(built))

    def call_stmt(self, items: list[ast.Call]) -> ast.CallStmt:
        return ast.CallStmt(items[0].span, items[0])


class _Tables:
    """lark's LALR(1) tables for grammar.lark, with callbacks that build the AST."""

    def __init__(self) -> None:
        self.builder = _AstBuilder()
        cache = Path(tempfile.gettempdir()) / f"rl1-grammar-{lark.__version__}.cache"
        parser = lark.Lark(
            GRAMMAR.read_text(encoding="utf-8"),
            start="line",
            parser="lalr",
            lexer=_ScannerLexer,
            transformer=self.builder,
            cache=str(cache),
        )
        lalr = parser.parser.parser.parser
        self.start: int = lalr.parse_table.start_states["line"]
        # The table recompiled into plain values, so that the loop below does no
        # attribute lookups or Rule hashing: a shift is the next state (an int); a
        # reduction is (number of children, rule name, callback building the value).
        self.actions: dict[int, dict[str, int | _Reduction]] = {
            state: {
                symbol: target if action is Shift
                else (len(target.expansion), target.origin.name, lalr.callbacks[target])
                for symbol, (action, target) in row.items()
            }
            for state, row in lalr.parse_table.states.items()
        }


_Reduction = tuple[int, str, Callable[[list[Any]], Any]]
_END = Token("$END", "", 0)
_tables: _Tables | None = None


def _lalr_tables() -> _Tables:
    global _tables
    if _tables is None:
        _tables = _Tables()
    return _tables


def _run_lalr(tables: _Tables, tokens: Iterable[Token]) -> Any:
    """Shift/reduce `tokens` through the LALR tables; the value of the `line` rule."""
    actions = tables.actions
    states = [tables.start]
    values: list[Any] = []
    for token in itertools.chain(tokens, (_END,)):
        kind = token.type
        while True:
            action = actions[states[-1]].get(kind)
            if action is None:
                expected = {name for name in actions[states[-1]] if name.isupper()}
                raise _SyntaxError(None if token is _END else token, expected)
            if type(action) is int:
                states.append(action)
                values.append(token)
                break
            size, rule, build = action  # type: ignore[misc]
            if size:
                children = values[-size:]
                del states[-size:]
                del values[-size:]
            else:
                children = []
            value = build(children)
            if len(states) == 1 and rule == "line":
                return value
            values.append(value)
            states.append(actions[states[-1]][rule])  # type: ignore[arg-type]
    raise AssertionError("the LALR tables accept no input without reducing `line`")


def _syntax_error(line: int, error: ScanError | _SyntaxError, code: str) -> Diagnostic:
    if isinstance(error, ScanError):
        span = ast.Span(line, error.column + 1, line, error.column + 2)
        return _bad_character(span, error.character)
    token = error.token
    if token is None:
        column, width = len(code.rstrip()) + 1, 1
    else:
        column, width = token.column + 1, max(len(token.text), 1)
    span = ast.Span(line, column, line, column + width)
    if token is None:
        found = "the end of the line"
    elif token.type == "WORD":
        return _misused_word(span, token.text)
    elif token.type == "LABEL":
        return Diagnostic(
            "E0104", Severity.ERROR,
            f"the label `{_excerpt(token.text)}` is not at the start of its line",
            span, help="a label `:NN` may only start a line: move it to a line of its own",
        )
    else:
        found = f"`{_excerpt(token.text)}`"
    expected = sorted({TERMINAL_NAMES.get(name, name) for name in error.expected})
    return Diagnostic(
        "E0101", Severity.ERROR,
        f"expected {_either(expected)}, found {found}", span,
        help=_syntax_help(token.text if token else "", error.expected),
    )


def _either(names: list[str]) -> str:
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " or " + names[-1]


def _syntax_help(found: str, expected: set[str]) -> str | None:
    if "VAR" in expected and "NUMBER" in expected and found.startswith("-"):
        return "there is no unary minus on a variable: write `0-V` for the negative of V"
    if expected == {"RPAR"} or ("RPAR" in expected and "_COMMA" in expected):
        return "close the call with `)`"
    if "LABELREF" in expected:
        return "a jump target is `#` and two digits, e.g. `#10`"
    return None


def _bad_character(span: ast.Span, character: str) -> Diagnostic:
    ascii_form = unicodedata.normalize("NFKC", character)
    if ascii_form != character and ascii_form.isascii() and ascii_form.strip():
        help_text = f"this is a full-width character: type the ASCII `{ascii_form}` instead"
    elif character == "\u3000":
        help_text = "this is a full-width space: type an ASCII space instead"
    else:
        help_text = "RL/I code is ASCII; text in any script may follow `'` as a comment"
    name = unicodedata.name(character, f"U+{ord(character):04X}")
    return Diagnostic("E0102", Severity.ERROR,
                      f"unexpected character `{character}` ({name})", span, help=help_text)


def _excerpt(text: str, limit: int = 24) -> str:
    """Token text short enough to quote in a message (the span still marks all of it)."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _misused_word(span: ast.Span, word: str) -> Diagnostic:
    if word.upper() in BUILTINS:
        return Diagnostic(
            "E0103", Severity.ERROR,
            f"`{word}` is a built-in function, which is called in parentheses", span,
            help=f"write `({word.upper()} ...)`",
        )
    return Diagnostic(
        "E0103", Severity.ERROR,
        f"`{_excerpt(word)}` is not a variable: variable names are one letter",
        span, help="use one of A-Z, a-z or @; built-in functions are written `(NAME ...)`",
    )


def parse_line(text: str, number: int) -> tuple[ast.Line, list[Diagnostic]]:
    """Parse one line of source (no line end) as line `number`."""
    code, quote, comment_text = text.partition("'")
    comment = None
    if quote:
        start = len(code) + 1
        comment = ast.Comment(ast.Span(number, start, number, len(text) + 1), comment_text)
    span = ast.Span(number, 1, number, len(text) + 1)
    if not code.strip(WHITESPACE):
        return ast.Line(span, number, None, (), comment), []
    tables = _lalr_tables()
    builder = tables.builder
    builder.line_number = number
    builder.problems = []
    try:
        label, statements = cast(_ParsedLine, _run_lalr(tables, scan(code)))
    except (ScanError, _SyntaxError) as error:
        return ast.Line(span, number, _leading_label(builder, code), (), comment, ok=False), [
            _syntax_error(number, error, code)
        ]
    return ast.Line(span, number, label, statements, comment), builder.problems


def _leading_label(builder: _AstBuilder, code: str) -> ast.LabelDef | None:
    """The label that starts a line with a syntax error, so that jumps to it still
    resolve and the checker need not assume the worst about the broken line."""
    try:
        first = next(scan(code), None)
    except ScanError:
        return None
    return builder.label_def(first) if first is not None and first.type == "LABEL" else None


def parse_program(text: str) -> tuple[ast.Program, list[Diagnostic]]:
    """Parse a whole source text; the diagnostics are the syntax errors of every line."""
    lines: list[ast.Line] = []
    diagnostics: list[Diagnostic] = []
    # The AST is acyclic, so the cyclic collector has nothing to find; left on, it
    # re-scans the growing tree and makes parsing time grow faster than the file.
    collecting = gc.isenabled()
    gc.disable()
    try:
        for number, line_text in enumerate(split_lines(text), start=1):
            line, problems = parse_line(line_text, number)
            lines.append(line)
            diagnostics.extend(problems)
    finally:
        if collecting:
            gc.enable()
    end = lines[-1].span if lines else ast.Span(1, 1, 1, 1)
    return ast.Program(ast.Span(1, 1, end.end_line, end.end_column), tuple(lines)), diagnostics
