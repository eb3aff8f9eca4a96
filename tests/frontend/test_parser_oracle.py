"""The parser against lark's own LALR parser.

The parser runs lark's tables through its own loop, once per sequence of token kinds,
and replays the outcome for every line with those kinds (compiler/frontend/parser.py). Here lark
parses the same tokens itself, with a tree builder written independently of
compiler/frontend/builders.py; both must build the same AST, or reject the line at the same
token expecting the same terminals.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any, cast

import lark
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lark.lexer import Lexer

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.make_tables import GRAMMAR, TABLES, generate
from rl1.compiler.frontend.parser import make_plan, parse_line
from rl1.compiler.frontend.scanner import scan
from rl1.compiler.strategies import lines
from rl1.vm.language import BUILTINS


class _ScannerTokens(Lexer):
    """Hands lark the tokens of compiler/frontend/scanner.py."""

    def __init__(self, lexer_conf: object) -> None:
        pass

    def lex(self, text: str) -> Iterator[lark.Token]:  # type: ignore[override]
        kinds, lexemes = scan(text)
        for kind, (text, column) in zip(kinds, lexemes, strict=True):
            yield lark.Token(kind, text, start_pos=column, column=column)


class _Reference(lark.Transformer):  # type: ignore[type-arg]
    """The AST from lark's parse tree, the way the spec describes each construct."""

    def __init__(self, line: int) -> None:
        super().__init__()
        self.number = line

    def _span(self, token: lark.Token) -> ast.Span:
        assert token.column is not None
        return ast.Span(self.number, token.column + 1, self.number, token.column + 1 + len(token))

    def _leaf(self, item: lark.Token | ast.Call) -> ast.Var | ast.Const | ast.Call:
        if isinstance(item, ast.Call):
            return item
        if item.type == "VAR":
            return ast.Var(self._span(item), str(item))
        if item.type == "NUMBER":
            return ast.Const(self._span(item), int(item), str(item), False)
        pattern = int(item[1:], 16)
        return ast.Const(self._span(item), pattern - 65536 if pattern > 32767 else pattern,
                         str(item), True)

    def _cover(self, first: ast.Span, last: ast.Span) -> ast.Span:
        return ast.Span(self.number, first.column, self.number, last.end_column)

    def line(self, items: list[Any]) -> tuple[ast.LabelDef | None, tuple[Any, ...]]:
        label = None
        if items and isinstance(items[0], lark.Token):
            token = items.pop(0)
            digits = token[1:]
            label = ast.LabelDef(self._span(token), str(token),
                                 int(digits) if len(digits) == 2 else None)
        return label, tuple(items)

    def assign(self, items: list[Any]) -> ast.Assign:
        target, _, first, *steps = items
        operand = self._leaf(first)
        var = ast.Var(self._span(target), str(target))
        return ast.Assign(self._cover(var.span, (steps[-1] if steps else operand).span),
                          var, operand, tuple(steps))

    def step(self, items: list[Any]) -> ast.BinaryStep:
        op, item = items
        operand = self._leaf(item)
        return ast.BinaryStep(self._cover(self._span(op), operand.span),
                              cast("ast.BinaryOperator", str(op)),
                              self._span(op), operand)

    def incdec(self, items: list[lark.Token]) -> ast.IncDec:
        var = ast.Var(self._span(items[0]), str(items[0]))
        return ast.IncDec(self._cover(var.span, self._span(items[1])), var,
                          cast("ast.Step", str(items[1])))

    def _label_ref(self, token: lark.Token) -> ast.LabelRef:
        digits = token[1:]
        return ast.LabelRef(self._span(token), str(token),
                            int(digits) if len(digits) == 2 else None)

    def goto(self, items: list[lark.Token]) -> ast.Goto:
        target = self._label_ref(items[0])
        return ast.Goto(target.span, target)

    def condjump(self, items: list[lark.Token]) -> ast.CondJump:
        qmark, var, relation, target = items
        label = self._label_ref(target)
        return ast.CondJump(self._cover(self._span(qmark), label.span),
                            ast.Var(self._span(var), str(var)),
                            cast("ast.Relation", str(relation)), label)

    def call(self, items: list[lark.Token]) -> ast.Call:
        lpar, mnemonic, *args, rpar = items
        builtin = BUILTINS.get(mnemonic.upper())
        built: list[ast.Arg] = []
        for index, arg in enumerate(args):
            if index == 0 and arg.type == "VAR" and builtin is not None and builtin.has_selector:
                built.append(ast.Selector(self._span(arg), str(arg)))
            else:
                built.append(self._leaf(arg))  # type: ignore[arg-type]
        return ast.Call(self._cover(self._span(lpar), self._span(rpar)), str(mnemonic),
                        self._span(mnemonic), tuple(built))

    def call_stmt(self, items: list[ast.Call]) -> ast.CallStmt:
        return ast.CallStmt(items[0].span, items[0])


_LARK = lark.Lark(GRAMMAR.read_text(encoding="utf-8"), start="line", parser="lalr",
                  lexer=_ScannerTokens)


def _lark_outcome(code: str) -> object:
    """lark's AST for the line, or where it stopped and what it expected there."""
    try:
        tree = _LARK.parse(code)
    except lark.exceptions.UnexpectedToken as error:
        at = None if error.token.type == "$END" else error.token.start_pos
        return ("rejected", at, frozenset(name for name in error.expected if name.isupper()))
    return _Reference(1).transform(tree)


def _our_outcome(code: str) -> object:
    kinds, lexemes = scan(code)
    plan = make_plan(kinds)
    if callable(plan):
        return plan(lexemes, ast.Row(1))
    at = None if plan.token is None else lexemes[plan.token][1]
    return ("rejected", at, plan.expected)


# Fragments that scan as every kind of token, mixed at random: mostly broken lines.
_FRAGMENTS = ["A", "x", "@", "=", "+", "-", "&", "|", "^", "<", ">", "?", "(", ")", ",", ";",
              "MOV", "CAM", "ULT", "P", "5", "-7", "$FF", "$8000", "$G1", "#10", "#5",
              ":10", ":", "++", "--", "AB", "．", " ", "\t"]


@settings(max_examples=400, deadline=None)
@given(st.one_of(lines(), st.lists(st.sampled_from(_FRAGMENTS), max_size=14).map("".join)))
def test_the_parser_builds_what_lark_builds(text: str) -> None:
    code = text.partition("'")[0]
    if not scan(code)[0]:
        return  # a blank line never reaches the tables
    assert _our_outcome(code) == _lark_outcome(code)


@pytest.mark.parametrize("code", ["C=a<3+b>6+C", ":21 (MOV 0,0); @=-5; D=0", "(CAM P c)",
                                  "A=(MOV 1", "A=1 B=2", ";;", ":10", "?A<#10; #12"])
def test_named_lines_parse_as_lark_parses_them(code: str) -> None:
    assert _our_outcome(code) == _lark_outcome(code)


def test_a_cached_plan_builds_the_same_line_as_a_fresh_one() -> None:
    first, _ = parse_line("A=B+1; (MOV 3,c)", 4)
    again, _ = parse_line("q=r-99;(MOV x 2)", 4)
    assert [type(s) for s in again.statements] == [type(s) for s in first.statements]
    assert again.statements[0] == ast.Assign(
        ast.Span(4, 1, 4, 7), ast.Var(ast.Span(4, 1, 4, 2), "q"),
        ast.Var(ast.Span(4, 3, 4, 4), "r"),
        (ast.BinaryStep(ast.Span(4, 4, 4, 7), "-", ast.Span(4, 4, 4, 5),
                        ast.Const(ast.Span(4, 5, 4, 7), 99, "99", False)),),
    )


def test_the_committed_tables_are_lark_s_analysis_of_the_grammar() -> None:
    assert TABLES.read_text(encoding="utf-8") == generate(), (
        "grammar.lark changed: run `python -m rl1.compiler.frontend.make_tables`"
    )
