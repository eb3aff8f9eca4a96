"""The RL/I abstract syntax tree: small immutable classes, separate from parsing.

Every node carries a `Span`. Nodes are treated as immutable (make changed copies with
`dataclasses.replace`) and hash by value; they are not declared `frozen` only because
frozen dataclasses are built several times slower, and parsing builds millions of them.
Lines are the unit of parsing (RL/I is line-oriented), so a `Line` can be re-parsed
alone and moved to another line number with `relocate`.

Walk a tree with a `Visitor` subclass: `visit(node)` calls `visit_<ClassName>`, falling
back to `generic_visit`, which visits the children.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, fields
from typing import Literal

BinaryOperator = Literal["+", "-", "&", "|", "^", "<", ">"]
Relation = Literal["=", ">", "<"]
Step = Literal["++", "--"]


@dataclass(slots=True, unsafe_hash=True)
class Span:
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


@dataclass(slots=True, unsafe_hash=True)
class Node:
    span: Span

    def children(self) -> Iterator[Node]:
        for field in fields(self):
            value = getattr(self, field.name)
            if isinstance(value, Node):
                yield value
            elif isinstance(value, tuple):
                yield from (item for item in value if isinstance(item, Node))


# Operands and arguments -------------------------------------------------------------


@dataclass(slots=True, unsafe_hash=True)
class Var(Node):
    """A one-letter variable: `A`-`Z`, `a`-`z` or `@`."""

    name: str


@dataclass(slots=True, unsafe_hash=True)
class Const(Node):
    """A constant as written. `value` is the number written (a decimal may lie outside
    16 bits; the checker reports it); `hex` constants are 16-bit bit patterns."""

    value: int
    text: str
    hex: bool


@dataclass(slots=True, unsafe_hash=True)
class Selector(Node):
    """The letter that selects a form of `(CAM ...)` or a sensor of `(ULT ...)`."""

    letter: str


Arg = Var | Const | Selector


@dataclass(slots=True, unsafe_hash=True)
class Call(Node):
    """A built-in function call `(MNEMONIC args)`; `mnemonic` is as written."""

    mnemonic: str
    mnemonic_span: Span
    args: tuple[Arg, ...]


Operand = Var | Const | Call


# Statements -------------------------------------------------------------------------


@dataclass(slots=True, unsafe_hash=True)
class BinaryStep(Node):
    """One `op operand` of a left-to-right expression."""

    op: BinaryOperator
    op_span: Span
    operand: Operand


@dataclass(slots=True, unsafe_hash=True)
class Assign(Node):
    """`V=operand {op operand}`, evaluated strictly left to right."""

    target: Var
    first: Operand
    rest: tuple[BinaryStep, ...]


@dataclass(slots=True, unsafe_hash=True)
class IncDec(Node):
    """`V++` or `V--`."""

    target: Var
    step: Step


@dataclass(slots=True, unsafe_hash=True)
class LabelRef(Node):
    """`#NN` as written; `number` is None when the digits are not a valid label."""

    text: str
    number: int | None


@dataclass(slots=True, unsafe_hash=True)
class Goto(Node):
    target: LabelRef


@dataclass(slots=True, unsafe_hash=True)
class CondJump(Node):
    """`?V=#NN`, `?V>#NN`, `?V<#NN`: jump when V compares so with zero."""

    var: Var
    relation: Relation
    target: LabelRef


@dataclass(slots=True, unsafe_hash=True)
class CallStmt(Node):
    call: Call


Statement = Assign | IncDec | Goto | CondJump | CallStmt


# Lines and programs -----------------------------------------------------------------


@dataclass(slots=True, unsafe_hash=True)
class LabelDef(Node):
    """`:NN` at the start of a line; `number` is None when not exactly two digits."""

    text: str
    number: int | None


@dataclass(slots=True, unsafe_hash=True)
class Comment(Node):
    """`' text` to the end of the line; `text` excludes the quote."""

    text: str


@dataclass(slots=True, unsafe_hash=True)
class Line(Node):
    """One source line. `ok` is False when the line has a syntax error; its
    statements are then empty and the parser's diagnostic says why."""

    number: int
    label: LabelDef | None
    statements: tuple[Statement, ...]
    comment: Comment | None
    ok: bool = True


@dataclass(slots=True, unsafe_hash=True)
class Program(Node):
    lines: tuple[Line, ...]

    def statements(self) -> Iterator[Statement]:
        for line in self.lines:
            yield from line.statements


def relocate(node: Node, line: int) -> Node:
    """A copy of a one-line node (and its children) moved to `line`. The language
    server moves every line below an inserted one, so this is built for speed: each
    class's fields are looked up once and nodes are rebuilt positionally."""
    values = []
    for name in _field_names(type(node)):
        value = getattr(node, name)
        if value.__class__ is Span:
            value = value.on_line(line)
        elif isinstance(value, Node):
            value = relocate(value, line)
        elif value.__class__ is tuple and value:
            value = tuple(relocate(item, line) if isinstance(item, Node) else item
                          for item in value)
        elif name == "number" and node.__class__ is Line:
            value = line
        values.append(value)
    return type(node)(*values)


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}


def _field_names(cls: type) -> tuple[str, ...]:
    names = _FIELD_NAMES.get(cls)
    if names is None:
        names = _FIELD_NAMES[cls] = tuple(field.name for field in fields(cls))
    return names


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
