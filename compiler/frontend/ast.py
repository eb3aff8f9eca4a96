"""The RL/I abstract syntax tree: small value classes, separate from parsing.

Every node carries a `Span`. Nodes are plain classes with slots, values never changed
after they are built. Lines are the unit of parsing (RL/I is line-oriented), so a
`Line` can be parsed alone; its spans share one `Row`, the line's number, so that the
language server moves a line (and every node and per-line diagnostic on it) by
renumbering its row, without rebuilding anything. `walk` visits a tree in source order.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from operator import attrgetter
from typing import Literal

BinaryOperator = Literal["+", "-", "&", "|", "^", "<", ">"]
Relation = Literal["=", ">", "<"]
Step = Literal["++", "--"]


class Row:
    """The number of a line that may move. Every span the parser makes on a line refers
    to the line's row, so renumbering the row moves them all (the language server does
    when an edit above inserts or deletes lines)."""

    __slots__ = ("number",)

    def __init__(self, number: int) -> None:
        self.number = number

    def __repr__(self) -> str:
        return f"Row({self.number})"


_COLUMNS: dict[int, int] = {}
"""One int object for each column number past 256, which CPython does not share: the
spans of a long line would otherwise hold two ints of their own each, a quarter of the
line's tree."""


class Span:
    """A source range. Lines and columns are 1-based; columns count code points and
    `end_column` is exclusive (one past the last character), as in SARIF.

    `Span(line, column, end_line, end_column)` with numbers makes a span of its own;
    with a `Row` for both lines it is a one-line span on that row, whose lines follow
    the row. A hand-written class rather than a dataclass: it takes either form, its
    lines are read through the row, and it is the parser's commonest object, built
    faster by a plain `__init__` than by a frozen dataclass's. Compared and hashed by
    the lines and columns it has now: a span on a row must not be a dict key while its
    row may be renumbered."""

    __slots__ = ("column", "end_column", "height", "row")

    def __init__(self, line: int | Row, column: int, end_line: int | Row,
                 end_column: int) -> None:
        if isinstance(line, Row):
            self.row = line
            self.height = 0
        else:
            assert isinstance(end_line, int)
            self.row = Row(line)
            self.height = end_line - line
        self.column = column if column <= 256 else _COLUMNS.setdefault(column, column)
        self.end_column = (end_column if end_column <= 256
                           else _COLUMNS.setdefault(end_column, end_column))

    @property
    def line(self) -> int:
        return self.row.number

    @property
    def end_line(self) -> int:
        return self.row.number + self.height

    def _key(self) -> tuple[int, int, int, int]:
        line = self.row.number
        return line, self.column, line + self.height, self.end_column

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Span) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        line, column, end_line, end_column = self._key()
        return (f"Span(line={line}, column={column}, end_line={end_line}, "
                f"end_column={end_column})")

    def cover(self, other: Span) -> Span:
        """The smallest span holding both (on their row, when they share one)."""
        if self.row is other.row and self.height == other.height == 0:
            return Span(self.row, min(self.column, other.column), self.row,
                        max(self.end_column, other.end_column))
        start = min((self.line, self.column), (other.line, other.column))
        end = max((self.end_line, self.end_column), (other.end_line, other.end_column))
        return Span(start[0], start[1], end[0], end[1])

    def end_to_end_of(self, other: Span) -> Span:
        """From the end of this span to the end of `other` (on their row, when they
        share one)."""
        if self.row is other.row and self.height == other.height == 0:
            return Span(self.row, self.end_column, self.row, other.end_column)
        return Span(self.end_line, self.end_column, other.end_line, other.end_column)

    def contains(self, line: int, column: int) -> bool:
        return (self.line, self.column) <= (line, column) < (self.end_line, self.end_column)


class Node:
    """The base of every node. Nodes are never changed once built, but not frozen
    classes: a frozen class's `__init__` takes more than twice as long, and the
    parser builds about ten nodes per line (bench/parse_check.py).

    Node classes are plain classes, as pycparser's are: `__slots__` holds the fields and
    `__init__` takes them, in their order, `span` first; equality, hashing and
    `repr` by the fields' values are written once, here. As dataclasses they cost 0.4 ms
    a class to define, 6 ms of every start of `rl1c check` (bench/cold_start.py)."""

    __slots__ = ("span",)

    def __init__(self, span: Span) -> None:
        self.span = span

    def _values(self) -> tuple[object, ...]:
        return _layout(type(self)).values(self)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Node) and type(other) is type(self)
                and self._values() == other._values())

    def __hash__(self) -> int:
        return hash((type(self), self._values()))

    def fields(self) -> Iterator[tuple[str, object]]:
        """The fields' names and values, in order."""
        return zip(_layout(type(self)).names, self._values(), strict=True)

    def __repr__(self) -> str:
        shown = ", ".join(f"{name}={value!r}" for name, value in self.fields())
        return f"{type(self).__name__}({shown})"

    def children(self) -> Iterator[Node]:
        for name in _layout(type(self)).child_names:
            value = getattr(self, name)
            if isinstance(value, Node):
                yield value
            elif isinstance(value, tuple):
                yield from (item for item in value if isinstance(item, Node))


class _Layout:
    """What the base needs to know of a node class: its fields' names, the names of
    those that may hold child nodes, and a getter of all their values."""

    __slots__ = ("child_names", "names", "values")

    def __init__(self, node_class: type[Node]) -> None:
        code = node_class.__init__.__code__  # the fields in order: its parameters
        self.names = code.co_varnames[1:code.co_argcount]
        self.child_names = tuple(name for name in self.names if name != "span")
        get = attrgetter(*self.names)
        # attrgetter of one name gives the value alone, not a tuple.
        self.values: Callable[[Node], tuple[object, ...]] = (
            (lambda node: (get(node),)) if len(self.names) == 1 else get)


_LAYOUTS: dict[type, _Layout] = {}


def _layout(node_class: type[Node]) -> _Layout:
    layout = _LAYOUTS.get(node_class)
    if layout is None:
        layout = _LAYOUTS[node_class] = _Layout(node_class)
    return layout


# Operands and arguments -------------------------------------------------------------


class Var(Node):
    """A one-letter variable: `A`-`Z`, `a`-`z` or `@`."""

    __slots__ = ("name",)

    def __init__(self, span: Span, name: str) -> None:
        self.span = span
        self.name = name


class Const(Node):
    """A constant as written. `value` is the number written (a decimal may lie outside
    16 bits; the checker reports it); `hex` constants are 16-bit bit patterns."""

    __slots__ = ("hex", "text", "value")

    def __init__(self, span: Span, value: int, text: str, hex: bool) -> None:
        self.span = span
        self.value = value
        self.text = text
        self.hex = hex


class Selector(Node):
    """The letter that selects a form of `(CAM ...)` or a sensor of `(ULT ...)`."""

    __slots__ = ("letter",)

    def __init__(self, span: Span, letter: str) -> None:
        self.span = span
        self.letter = letter


Arg = Var | Const | Selector


class Call(Node):
    """A built-in function call `(MNEMONIC args)`; `mnemonic` is as written."""

    __slots__ = ("args", "mnemonic", "mnemonic_span")

    def __init__(self, span: Span, mnemonic: str, mnemonic_span: Span, args: tuple[Arg,
                 ...]) -> None:
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

    def __init__(self, span: Span, op: BinaryOperator, op_span: Span, operand: Operand) -> None:
        self.span = span
        self.op = op
        self.op_span = op_span
        self.operand = operand


class Assign(Node):
    """`V=operand {op operand}`, evaluated strictly left to right."""

    __slots__ = ("first", "rest", "target")

    def __init__(self, span: Span, target: Var, first: Operand, rest: tuple[BinaryStep,
                 ...]) -> None:
        self.span = span
        self.target = target
        self.first = first
        self.rest = rest


class IncDec(Node):
    """`V++` or `V--`."""

    __slots__ = ("step", "target")

    def __init__(self, span: Span, target: Var, step: Step) -> None:
        self.span = span
        self.target = target
        self.step = step


class LabelRef(Node):
    """`#NN` as written; `number` is None when the digits are not a valid label."""

    __slots__ = ("number", "text")

    def __init__(self, span: Span, text: str, number: int | None) -> None:
        self.span = span
        self.text = text
        self.number = number


class Goto(Node):
    __slots__ = ("target",)

    def __init__(self, span: Span, target: LabelRef) -> None:
        self.span = span
        self.target = target


class CondJump(Node):
    """`?V=#NN`, `?V>#NN`, `?V<#NN`: jump when V compares so with zero."""

    __slots__ = ("relation", "target", "var")

    def __init__(self, span: Span, var: Var, relation: Relation, target: LabelRef) -> None:
        self.span = span
        self.var = var
        self.relation = relation
        self.target = target


class CallStmt(Node):
    __slots__ = ("call",)

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

    __slots__ = ("number", "text")

    def __init__(self, span: Span, text: str, number: int | None) -> None:
        self.span = span
        self.text = text
        self.number = number


class Comment(Node):
    """`' text` to the end of the line; `text` excludes the quote."""

    __slots__ = ("text",)

    def __init__(self, span: Span, text: str) -> None:
        self.span = span
        self.text = text


class Line(Node):
    """One source line. `ok` is False when the line has a syntax error; its
    statements are then empty and the parser's diagnostic says why."""

    __slots__ = ("comment", "label", "ok", "statements")

    def __init__(self, span: Span, label: LabelDef | None, statements: tuple[Statement, ...],
                 comment: Comment | None, ok: bool = True) -> None:
        self.span = span
        self.label = label
        self.statements = statements
        self.comment = comment
        self.ok = ok

    @property
    def number(self) -> int:
        """The line's 1-based number, now (its row's)."""
        return self.span.row.number


class Program(Node):
    __slots__ = ("lines",)

    def __init__(self, span: Span, lines: tuple[Line, ...]) -> None:
        self.span = span
        self.lines = lines

    def statements(self) -> Iterator[Statement]:
        for line in self.lines:
            yield from line.statements


def walk(node: Node) -> Iterator[Node]:
    """Every node under `node`, `node` first, in source order."""
    yield node
    for child in node.children():
        yield from walk(child)
