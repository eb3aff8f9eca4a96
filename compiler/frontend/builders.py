"""The parser's semantic actions: for each rule of grammar.lark, how its AST node is
built from a line's lexemes.

The parser works out, once for each sequence of token kinds, which rules a line reduces
and in what order (see parser.py). It calls the action of each rule then, with the
rule's children: the index of a token in the line, or the builder already made for a
sub-rule. The action returns a *builder*: a function from the lexemes and the number of
any line with those kinds to the node. So the work that depends only on the kinds
(which token is which, which class to make) is done once, and a builder only reads
texts and columns.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from rl1.vm.language import BUILTINS, decimal_value

from . import ast
from .scanner import Kinds, Lexeme

Node = TypeVar("Node", covariant=True)
Builder = Callable[[Sequence[Lexeme], ast.Row], Node]
"""Builds a node from a line's lexemes and its row (the line number its spans share)."""

Child = int | Builder[Any]
"""What a rule receives for each symbol: a token's index, or a sub-rule's builder."""

ParsedLine = tuple[ast.LabelDef | None, tuple[ast.Statement, ...]]

Letter = TypeVar("Letter", ast.Var, ast.Selector)

_SELECTING = frozenset(name for name, builtin in BUILTINS.items() if builtin.has_selector)


def label_def(lexemes: Sequence[Lexeme], line: ast.Row, index: int = 0) -> ast.LabelDef:
    text, column = lexemes[index]
    return ast.LabelDef(ast.Span(line, column + 1, line, column + 1 + len(text)), text,
                        _label_number(text))


def _label_number(text: str) -> int | None:
    """The number of `:NN` or `#NN`; None unless exactly two digits follow."""
    digits = text[1:]
    return int(digits) if len(digits) == 2 else None


def _label_ref(index: int) -> Builder[ast.LabelRef]:
    def build(lexemes: Sequence[Lexeme], line: ast.Row) -> ast.LabelRef:
        text, column = lexemes[index]
        return ast.LabelRef(ast.Span(line, column + 1, line, column + 1 + len(text)), text,
                            _label_number(text))
    return build


def _letter(node: type[Letter], index: int) -> Builder[Letter]:
    """A variable, or the selector letter of `(CAM P c)` and `(ULT A)`."""
    def build(lexemes: Sequence[Lexeme], line: ast.Row) -> Letter:
        text, column = lexemes[index]
        return node(ast.Span(line, column + 1, line, column + 2), text)
    return build


def _var(index: int) -> Builder[ast.Var]:
    return _letter(ast.Var, index)


def _number(index: int) -> Builder[ast.Const]:
    def build(lexemes: Sequence[Lexeme], line: ast.Row) -> ast.Const:
        text, column = lexemes[index]
        return ast.Const(ast.Span(line, column + 1, line, column + 1 + len(text)),
                         decimal_value(text), text, False)
    return build


def _hex(index: int) -> Builder[ast.Const]:
    """The scanner makes a HEX token only of a valid 16-bit pattern."""
    def build(lexemes: Sequence[Lexeme], line: ast.Row) -> ast.Const:
        text, column = lexemes[index]
        value = int(text[1:], 16)
        return ast.Const(ast.Span(line, column + 1, line, column + 1 + len(text)),
                         value - 0x10000 if value >= 0x8000 else value, text, True)
    return build


_LEAVES: dict[str, Callable[[int], Builder[ast.Var | ast.Const]]] = {
    "VAR": _var, "NUMBER": _number, "HEX": _hex,
}


def _operand(kinds: Kinds, child: Child) -> Builder[ast.Operand]:
    return _LEAVES[kinds[child]](child) if isinstance(child, int) else child


def line(kinds: Kinds, children: list[Child]) -> Builder[ParsedLine]:
    has_label = bool(children) and isinstance(children[0], int)
    statements: list[Builder[ast.Statement]] = children[has_label:]  # type: ignore[assignment]

    if len(statements) == 1 and not has_label:  # the commonest line, made a little faster
        (only,) = statements

        def build_one(lexemes: Sequence[Lexeme], number: ast.Row) -> ParsedLine:
            return None, (only(lexemes, number),)
        return build_one

    def build(lexemes: Sequence[Lexeme], number: ast.Row) -> ParsedLine:
        return (label_def(lexemes, number) if has_label else None,
                tuple([statement(lexemes, number) for statement in statements]))
    return build


def assign(kinds: Kinds, children: list[Child]) -> Builder[ast.Assign]:
    target_index, _, first_child, *step_children = children
    assert isinstance(target_index, int)
    target = _var(target_index)
    first = _operand(kinds, first_child)
    steps: list[Builder[ast.BinaryStep]] = step_children  # type: ignore[assignment]

    def build(lexemes: Sequence[Lexeme], number: ast.Row) -> ast.Assign:
        target_var = target(lexemes, number)
        first_operand = first(lexemes, number)
        rest = tuple([step(lexemes, number) for step in steps]) if steps else ()
        end = rest[-1].span if rest else first_operand.span
        return ast.Assign(ast.Span(number, target_var.span.column, number, end.end_column),
                          target_var, first_operand, rest)
    return build


def step(kinds: Kinds, children: list[Child]) -> Builder[ast.BinaryStep]:
    op_index, operand_child = children
    assert isinstance(op_index, int)
    operand = _operand(kinds, operand_child)

    def build(lexemes: Sequence[Lexeme], number: ast.Row) -> ast.BinaryStep:
        op, column = lexemes[op_index]
        value = operand(lexemes, number)
        return ast.BinaryStep(ast.Span(number, column + 1, number, value.span.end_column),
                              op, ast.Span(number, column + 1, number, column + 2),  # type: ignore[arg-type]
                              value)
    return build


def incdec(kinds: Kinds, children: list[Child]) -> Builder[ast.IncDec]:
    var_index, step_index = children
    assert isinstance(var_index, int) and isinstance(step_index, int)
    target = _var(var_index)

    def build(lexemes: Sequence[Lexeme], number: ast.Row) -> ast.IncDec:
        target_var = target(lexemes, number)
        column = lexemes[step_index][1]
        return ast.IncDec(ast.Span(number, target_var.span.column, number, column + 3),
                          target_var, lexemes[step_index][0])  # type: ignore[arg-type]
    return build


def goto(kinds: Kinds, children: list[Child]) -> Builder[ast.Goto]:
    (target_index,) = children
    assert isinstance(target_index, int)
    target = _label_ref(target_index)

    def build(lexemes: Sequence[Lexeme], number: ast.Row) -> ast.Goto:
        label = target(lexemes, number)
        return ast.Goto(label.span, label)
    return build


def condjump(kinds: Kinds, children: list[Child]) -> Builder[ast.CondJump]:
    qmark_index, var_index, relation_index, target_index = children
    assert isinstance(qmark_index, int) and isinstance(var_index, int)
    assert isinstance(relation_index, int) and isinstance(target_index, int)
    var, target = _var(var_index), _label_ref(target_index)

    def build(lexemes: Sequence[Lexeme], number: ast.Row) -> ast.CondJump:
        label = target(lexemes, number)
        return ast.CondJump(
            ast.Span(number, lexemes[qmark_index][1] + 1, number, label.span.end_column),
            var(lexemes, number), lexemes[relation_index][0], label,  # type: ignore[arg-type]
        )
    return build


def call_stmt(kinds: Kinds, children: list[Child]) -> Builder[ast.CallStmt]:
    (call_builder,) = children
    assert not isinstance(call_builder, int)

    def build(lexemes: Sequence[Lexeme], number: ast.Row) -> ast.CallStmt:
        call_node = call_builder(lexemes, number)
        return ast.CallStmt(call_node.span, call_node)
    return build


def call(kinds: Kinds, children: list[Child]) -> Builder[ast.Call]:
    lpar_index, mnemonic_index, *arg_children, rpar_index = children
    assert isinstance(lpar_index, int) and isinstance(mnemonic_index, int)
    assert isinstance(rpar_index, int)
    arg_indices: list[int] = arg_children  # type: ignore[assignment]  # single tokens, by the grammar
    args = [_LEAVES[kinds[index]](index) for index in arg_indices]
    # `(CAM P c)`: a letter first selects a form; whether this call is a CAM or an ULT is
    # in the mnemonic's text, which the kinds do not tell, so the builder decides.
    first_is_letter = bool(arg_indices) and kinds[arg_indices[0]] == "VAR"
    selector = _letter(ast.Selector, arg_indices[0]) if first_is_letter else None

    def build(lexemes: Sequence[Lexeme], number: ast.Row) -> ast.Call:
        mnemonic, column = lexemes[mnemonic_index]
        if selector is not None and mnemonic.upper() in _SELECTING:
            built: tuple[ast.Arg, ...] = (selector(lexemes, number),
                                          *[arg(lexemes, number) for arg in args[1:]])
        else:
            built = tuple([arg(lexemes, number) for arg in args])
        return ast.Call(
            ast.Span(number, lexemes[lpar_index][1] + 1, number, lexemes[rpar_index][1] + 2),
            mnemonic, ast.Span(number, column + 1, number, column + 1 + len(mnemonic)), built,
        )
    return build


ACTIONS: dict[str, Callable[[Kinds, list[Child]], Builder[Any]]] = {
    "line": line, "assign": assign, "step": step, "incdec": incdec, "goto": goto,
    "condjump": condjump, "call_stmt": call_stmt, "call": call,
}
"""The action of each rule that makes a node; the others pass their children on."""
