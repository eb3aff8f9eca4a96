"""The RL/I abstract syntax tree: small immutable classes, separate from parsing.

Every node carries a `Span`. Nodes are msgspec Structs: frozen (make changed copies with
`msgspec.structs.replace`), compared and hashed by value, built three times faster than
slotted dataclasses, and, because a tree of them can hold no cycle, left untracked by
the cyclic garbage collector (`gc=False`), which would otherwise walk every node of a
large program after parsing it. Lines are the unit of parsing (RL/I is line-oriented),
so a `Line` can be re-parsed alone and moved to another line number with `relocate`.

Walk a tree with a `Visitor` subclass: `visit(node)` calls `visit_<ClassName>`, falling
back to `generic_visit`, which visits the children.
"""

from __future__ import annotations

import typing
from collections.abc import Iterator
from typing import Literal, NamedTuple

import msgspec

BinaryOperator = Literal["+", "-", "&", "|", "^", "<", ">"]
Relation = Literal["=", ">", "<"]
Step = Literal["++", "--"]


class Span(msgspec.Struct, frozen=True, gc=False):
    """A source range. Lines and columns are 1-based; columns count code points and
    `end_column` is exclusive (one past the last character), as in SARIF."""

    line: int
    column: int
    end_line: int
    end_column: int

    def on_line(self, line: int) -> Span:
        return Span(line, self.column, line + self.end_line - self.line, self.end_column)

    def cover(self, other: Span) -> Span:
        """The smallest span holding both."""
        start = min((self.line, self.column), (other.line, other.column))
        end = max((self.end_line, self.end_column), (other.end_line, other.end_column))
        return Span(start[0], start[1], end[0], end[1])

    def contains(self, line: int, column: int) -> bool:
        return (self.line, self.column) <= (line, column) < (self.end_line, self.end_column)


class Node(msgspec.Struct, frozen=True, gc=False):
    span: Span

    def children(self) -> Iterator[Node]:
        for name in self.__struct_fields__:
            value = getattr(self, name)
            if isinstance(value, Node):
                yield value
            elif isinstance(value, tuple):
                yield from (item for item in value if isinstance(item, Node))


# Operands and arguments -------------------------------------------------------------


class Var(Node, frozen=True, gc=False):
    """A one-letter variable: `A`-`Z`, `a`-`z` or `@`."""

    name: str


class Const(Node, frozen=True, gc=False):
    """A constant as written. `value` is the number written (a decimal may lie outside
    16 bits; the checker reports it); `hex` constants are 16-bit bit patterns."""

    value: int
    text: str
    hex: bool


class Selector(Node, frozen=True, gc=False):
    """The letter that selects a form of `(CAM ...)` or a sensor of `(ULT ...)`."""

    letter: str


Arg = Var | Const | Selector


class Call(Node, frozen=True, gc=False):
    """A built-in function call `(MNEMONIC args)`; `mnemonic` is as written."""

    mnemonic: str
    mnemonic_span: Span
    args: tuple[Arg, ...]


Operand = Var | Const | Call


# Statements -------------------------------------------------------------------------


class BinaryStep(Node, frozen=True, gc=False):
    """One `op operand` of a left-to-right expression."""

    op: BinaryOperator
    op_span: Span
    operand: Operand


class Assign(Node, frozen=True, gc=False):
    """`V=operand {op operand}`, evaluated strictly left to right."""

    target: Var
    first: Operand
    rest: tuple[BinaryStep, ...]


class IncDec(Node, frozen=True, gc=False):
    """`V++` or `V--`."""

    target: Var
    step: Step


class LabelRef(Node, frozen=True, gc=False):
    """`#NN` as written; `number` is None when the digits are not a valid label."""

    text: str
    number: int | None


class Goto(Node, frozen=True, gc=False):
    target: LabelRef


class CondJump(Node, frozen=True, gc=False):
    """`?V=#NN`, `?V>#NN`, `?V<#NN`: jump when V compares so with zero."""

    var: Var
    relation: Relation
    target: LabelRef


class CallStmt(Node, frozen=True, gc=False):
    call: Call


Statement = Assign | IncDec | Goto | CondJump | CallStmt


# Lines and programs -----------------------------------------------------------------


class LabelDef(Node, frozen=True, gc=False):
    """`:NN` at the start of a line; `number` is None when not exactly two digits."""

    text: str
    number: int | None


class Comment(Node, frozen=True, gc=False):
    """`' text` to the end of the line; `text` excludes the quote."""

    text: str


class Line(Node, frozen=True, gc=False):
    """One source line. `ok` is False when the line has a syntax error; its
    statements are then empty and the parser's diagnostic says why."""

    number: int
    label: LabelDef | None
    statements: tuple[Statement, ...]
    comment: Comment | None
    ok: bool = True


class Program(Node, frozen=True, gc=False):
    lines: tuple[Line, ...]

    def statements(self) -> Iterator[Statement]:
        for line in self.lines:
            yield from line.statements


def relocate(node: Node, line: int) -> Node:
    """A copy of a one-line node (and its children) moved to `line`. The language
    server moves every line below an inserted one, so this is built for speed: what to
    do with each field is worked out once per class, and nodes are rebuilt positionally."""
    cls = node.__class__
    plan = _RELOCATION_PLANS.get(cls) or _relocation_plan(cls)
    values = list(msgspec.structs.astuple(node))
    for index in plan.spans:
        span = values[index]
        values[index] = Span(line, span.column, line + span.end_line - span.line,
                             span.end_column)
    for index in plan.nodes:
        if values[index] is not None:
            values[index] = relocate(values[index], line)
    for index in plan.tuples:
        values[index] = tuple([relocate(item, line) for item in values[index]])
    if plan.number is not None:
        values[plan.number] = line
    return cls(*values)


class _RelocationPlan(NamedTuple):
    """The positions of a class's fields that hold a span, a node (or None), a tuple of
    nodes, and the line number (Line's)."""

    spans: tuple[int, ...]
    nodes: tuple[int, ...]
    tuples: tuple[int, ...]
    number: int | None


_RELOCATION_PLANS: dict[type, _RelocationPlan] = {}


def _relocation_plan(cls: type[Node]) -> _RelocationPlan:
    spans, nodes, tuples, number = [], [], [], None
    for index, field in enumerate(msgspec.structs.fields(cls)):
        if field.type is Span:
            spans.append(index)
        elif typing.get_origin(field.type) is tuple:
            tuples.append(index)
        elif cls is Line and field.name == "number":
            number = index
        elif any(isinstance(option, type) and issubclass(option, Node)
                 for option in (*typing.get_args(field.type), field.type)):
            nodes.append(index)
    plan = _RELOCATION_PLANS[cls] = _RelocationPlan(tuple(spans), tuple(nodes), tuple(tuples),
                                                    number)
    return plan


class Visitor:
    """Calls `visit_<ClassName>(node)`; `generic_visit` visits the children."""

    def visit(self, node: Node) -> object:
        method = getattr(self, "visit_" + type(node).__name__, self.generic_visit)
        return method(node)

    def generic_visit(self, node: Node) -> object:
        for child in node.children():
            self.visit(child)
        return None


def walk(node: Node) -> Iterator[Node]:
    """Every node under `node`, `node` first, in source order."""
    yield node
    for child in node.children():
        yield from walk(child)
