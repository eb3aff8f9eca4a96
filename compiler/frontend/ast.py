"""The RL/I abstract syntax tree: small value classes, separate from parsing.

Every node carries a `Span`. Nodes are `Record`s (record.py), as pycparser's are plain
classes: fields in `__slots__`, set once by `__init__`, compared and hashed by value; they
are values, never changed after they are built. Lines are the unit of parsing (RL/I is
line-oriented), so a `Line` can be re-parsed alone and moved to another line number with
`relocate`. `walk` visits a tree in source order.
"""

from __future__ import annotations

from collections.abc import Iterator
from types import UnionType

from .record import Record

TYPE_CHECKING = False  # `typing` costs 4 ms of every start (record.py)
if TYPE_CHECKING:
    from typing import Any, Literal

    BinaryOperator = Literal["+", "-", "&", "|", "^", "<", ">"]
    Relation = Literal["=", ">", "<"]
    Step = Literal["++", "--"]


class Span(Record):
    """A source range. Lines and columns are 1-based; columns count code points and
    `end_column` is exclusive (one past the last character), as in SARIF."""

    __slots__ = ("line", "column", "end_line", "end_column")
    line: int
    column: int
    end_line: int
    end_column: int

    def __init__(self, line: int, column: int, end_line: int, end_column: int) -> None:
        self.line = line
        self.column = column
        self.end_line = end_line
        self.end_column = end_column

    def on_line(self, line: int) -> Span:
        return Span(line, self.column, line + self.end_line - self.line, self.end_column)

    def cover(self, other: Span) -> Span:
        """The smallest span holding both."""
        start = min((self.line, self.column), (other.line, other.column))
        end = max((self.end_line, self.end_column), (other.end_line, other.end_column))
        return Span(start[0], start[1], end[0], end[1])

    def contains(self, line: int, column: int) -> bool:
        return (self.line, self.column) <= (line, column) < (self.end_line, self.end_column)


class Node(Record):
    __slots__ = ("span",)
    span: Span

    def children(self) -> Iterator[Node]:
        for name in self.fields:
            value = getattr(self, name)
            if isinstance(value, Node):
                yield value
            elif isinstance(value, tuple):
                yield from (item for item in value if isinstance(item, Node))


# Operands and arguments -------------------------------------------------------------


class Var(Node):
    """A one-letter variable: `A`-`Z`, `a`-`z` or `@`."""

    __slots__ = ("name",)
    name: str

    def __init__(self, span: Span, name: str) -> None:
        self.span = span
        self.name = name


class Const(Node):
    """A constant as written. `value` is the number written (a decimal may lie outside
    16 bits; the checker reports it); `hex` constants are 16-bit bit patterns."""

    __slots__ = ("value", "text", "hex")
    value: int
    text: str
    hex: bool

    def __init__(self, span: Span, value: int, text: str, hex: bool) -> None:
        self.span = span
        self.value = value
        self.text = text
        self.hex = hex


class Selector(Node):
    """The letter that selects a form of `(CAM ...)` or a sensor of `(ULT ...)`."""

    __slots__ = ("letter",)
    letter: str

    def __init__(self, span: Span, letter: str) -> None:
        self.span = span
        self.letter = letter


Arg = Var | Const | Selector


class Call(Node):
    """A built-in function call `(MNEMONIC args)`; `mnemonic` is as written."""

    __slots__ = ("mnemonic", "mnemonic_span", "args")
    mnemonic: str
    mnemonic_span: Span
    args: tuple[Arg, ...]

    def __init__(
        self, span: Span, mnemonic: str, mnemonic_span: Span, args: tuple[Arg, ...]
    ) -> None:
        self.span = span
        self.mnemonic = mnemonic
        self.mnemonic_span = mnemonic_span
        self.args = args

    @property
    def is_end(self) -> bool:
        """Whether this is `(END)`, in any case."""
        return self.mnemonic.upper() == "END"


Operand = Var | Const | Call


# Statements -------------------------------------------------------------------------


class BinaryStep(Node):
    """One `op operand` of a left-to-right expression."""

    __slots__ = ("op", "op_span", "operand")
    op: BinaryOperator
    op_span: Span
    operand: Operand

    def __init__(
        self, span: Span, op: BinaryOperator, op_span: Span, operand: Operand
    ) -> None:
        self.span = span
        self.op = op
        self.op_span = op_span
        self.operand = operand


class Assign(Node):
    """`V=operand {op operand}`, evaluated strictly left to right."""

    __slots__ = ("target", "first", "rest")
    target: Var
    first: Operand
    rest: tuple[BinaryStep, ...]

    def __init__(
        self, span: Span, target: Var, first: Operand, rest: tuple[BinaryStep, ...]
    ) -> None:
        self.span = span
        self.target = target
        self.first = first
        self.rest = rest


class IncDec(Node):
    """`V++` or `V--`."""

    __slots__ = ("target", "step")
    target: Var
    step: Step

    def __init__(self, span: Span, target: Var, step: Step) -> None:
        self.span = span
        self.target = target
        self.step = step


class LabelRef(Node):
    """`#NN` as written; `number` is None when the digits are not a valid label."""

    __slots__ = ("text", "number")
    text: str
    number: int | None

    def __init__(self, span: Span, text: str, number: int | None) -> None:
        self.span = span
        self.text = text
        self.number = number


class Goto(Node):
    __slots__ = ("target",)
    target: LabelRef

    def __init__(self, span: Span, target: LabelRef) -> None:
        self.span = span
        self.target = target


class CondJump(Node):
    """`?V=#NN`, `?V>#NN`, `?V<#NN`: jump when V compares so with zero."""

    __slots__ = ("var", "relation", "target")
    var: Var
    relation: Relation
    target: LabelRef

    def __init__(self, span: Span, var: Var, relation: Relation, target: LabelRef) -> None:
        self.span = span
        self.var = var
        self.relation = relation
        self.target = target


class CallStmt(Node):
    __slots__ = ("call",)
    call: Call

    def __init__(self, span: Span, call: Call) -> None:
        self.span = span
        self.call = call


Statement = Assign | IncDec | Goto | CondJump | CallStmt


def is_end(statement: Statement) -> bool:
    """Whether `statement` is `(END)`."""
    return isinstance(statement, CallStmt) and statement.call.is_end


# Lines and programs -----------------------------------------------------------------


class LabelDef(Node):
    """`:NN` at the start of a line; `number` is None when not exactly two digits."""

    __slots__ = ("text", "number")
    text: str
    number: int | None

    def __init__(self, span: Span, text: str, number: int | None) -> None:
        self.span = span
        self.text = text
        self.number = number


class Comment(Node):
    """`' text` to the end of the line; `text` excludes the quote."""

    __slots__ = ("text",)
    text: str

    def __init__(self, span: Span, text: str) -> None:
        self.span = span
        self.text = text


class Line(Node):
    """One source line. `ok` is False when the line has a syntax error; its
    statements are then empty and the parser's diagnostic says why."""

    __slots__ = ("number", "label", "statements", "comment", "ok")
    number: int
    label: LabelDef | None
    statements: tuple[Statement, ...]
    comment: Comment | None
    ok: bool

    def __init__(self, span: Span, number: int, label: LabelDef | None,
                 statements: tuple[Statement, ...], comment: Comment | None,
                 ok: bool = True) -> None:
        self.span = span
        self.number = number
        self.label = label
        self.statements = statements
        self.comment = comment
        self.ok = ok


class Program(Node):
    __slots__ = ("lines",)
    lines: tuple[Line, ...]

    def __init__(self, span: Span, lines: tuple[Line, ...]) -> None:
        self.span = span
        self.lines = lines

    def statements(self) -> Iterator[Statement]:
        for line in self.lines:
            yield from line.statements


def relocate(node: Node, line: int) -> Node:
    """A copy of a one-line node (and its children) moved to `line`. The language
    server moves every line below an inserted one, so this is built for speed: what to
    do with each field is worked out once per class, and nodes are rebuilt positionally."""
    cls = node.__class__
    plan = _RELOCATION_PLANS.get(cls) or _relocation_plan(cls)
    values: list[Any] = list(node.values())
    for index in plan.spans:
        values[index] = values[index].on_line(line)
    for index in plan.nodes:
        if values[index] is not None:
            values[index] = relocate(values[index], line)
    for index in plan.tuples:
        values[index] = tuple([relocate(item, line) for item in values[index]])
    if plan.number is not None:
        values[plan.number] = line
    return cls(*values)


class _RelocationPlan(Record):
    """The positions of a class's fields that hold a span, a node (or None), a tuple of
    nodes, and the line number (Line's)."""

    __slots__ = ("spans", "nodes", "tuples", "number")

    def __init__(self, spans: tuple[int, ...], nodes: tuple[int, ...], tuples: tuple[int, ...],
                 number: int | None) -> None:
        self.spans = spans
        self.nodes = nodes
        self.tuples = tuples
        self.number = number


_RELOCATION_PLANS: dict[type, _RelocationPlan] = {}


def _relocation_plan(cls: type[Node]) -> _RelocationPlan:
    """Read from the field annotations, which `from __future__ import annotations` keeps
    as the strings written above (`Span`, `tuple[Arg, ...]`, `LabelDef | None`...)."""
    annotations: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        annotations.update(getattr(klass, "__annotations__", {}))
    spans, nodes, tuples, number = [], [], [], None
    for index, name in enumerate(cls.fields):
        written = annotations[name]
        if written == "Span":
            spans.append(index)
        elif written.startswith("tuple["):
            tuples.append(index)
        elif cls is Line and name == "number":
            number = index
        elif any(_holds_nodes(globals().get(option.strip())) for option in written.split("|")):
            nodes.append(index)
    plan = _RELOCATION_PLANS[cls] = _RelocationPlan(tuple(spans), tuple(nodes), tuple(tuples),
                                                    number)
    return plan


def _holds_nodes(kind: object) -> bool:
    """Whether `kind` (a class or a union like `Operand`) is or includes a Node class."""
    if isinstance(kind, UnionType):
        return any(_holds_nodes(option) for option in kind.__args__)
    return isinstance(kind, type) and issubclass(kind, Node)


def walk(node: Node) -> Iterator[Node]:
    """Every node under `node`, `node` first, in source order."""
    yield node
    for child in node.children():
        yield from walk(child)
