"""Expected results computed from spec/language.md's rules alone (sections 6.1, 7.2, 7.3).

This is the generator's second opinion on arithmetic: it shares no code with the
compiler, the VM or the interpreter. Values are Python integers of any size; each rule
applies its wrap explicitly, as the spec words it. A `Straight` program (assignments and
++/-- only, no jumps) is rendered to RL/I source and evaluated here, so the generator
can hold the engines' final variables against this evaluation.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

VARIABLES = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz@"  # spec 6.2, index order
RESERVED = "stuvwxyz"
INT16_MIN, INT16_MAX = -32768, 32767


def wrap(value: int) -> int:
    """Spec 6.1: wrap(x) = ((x + 32768) mod 65536) - 32768."""
    return (value + 32768) % 65536 - 32768


def pattern(value: int) -> int:
    """The 16-bit two's-complement bit pattern of a 16-bit value, 0..65535."""
    return value % 65536


def from_pattern(bits: int) -> int:
    """The 16-bit value a bit pattern 0..65535 denotes (spec 3.3: `$FFFF` is -1)."""
    return bits - 65536 if bits >= 32768 else bits


def shift_left(value: int, count: int) -> int:
    """Spec 7.2: `a < n`. Counts 16 and above give 0; a negative count shifts right by
    -n (so -32768 shifts right by 32768)."""
    if count < 0:
        return shift_right(value, -count)
    if count >= 16:
        return 0
    return wrap(value * (1 << count))  # a x 2^n


def shift_right(value: int, count: int) -> int:
    """Spec 7.2: `a > n`, floor(a / 2^n). Counts 16 and above give 0 or -1 by the sign;
    a negative count shifts left by -n."""
    if count < 0:
        return shift_left(value, -count)
    if count >= 16:
        return -1 if value < 0 else 0
    return value // (1 << count)  # floor(a / 2^n): Python's // floors


OPERATORS: dict[str, Callable[[int, int], int]] = {
    "+": lambda a, b: wrap(a + b),
    "-": lambda a, b: wrap(a - b),
    "&": lambda a, b: from_pattern(pattern(a) & pattern(b)),
    "|": lambda a, b: from_pattern(pattern(a) | pattern(b)),
    "^": lambda a, b: from_pattern(pattern(a) ^ pattern(b)),
    "<": shift_left,
    ">": shift_right,
}


# Straight-line programs ---------------------------------------------------------------


@dataclass(frozen=True)
class Hex:
    """A `$hex` constant, written with these digits."""

    digits: str

    @property
    def value(self) -> int:
        return from_pattern(int(self.digits, 16))


@dataclass(frozen=True)
class Port:
    """An `(INP port)` operand: the port's next scripted reading (spec 7.4; the scripted
    device repeats a list's last reading once it runs out)."""

    port: int


Operand = int | str | Hex | Port  # a decimal constant, a variable name, hex, a port read


@dataclass(frozen=True)
class Assign:
    """`target=first op operand op operand ...`"""

    target: str
    first: Operand
    steps: tuple[tuple[str, Operand], ...] = ()


@dataclass(frozen=True)
class Step:
    """`target++` or `target--`"""

    target: str
    op: Literal["++", "--"]


Statement = Assign | Step


def render(operand: Operand) -> str:
    """An operand as RL/I source text."""
    if isinstance(operand, Hex):
        return "$" + operand.digits
    if isinstance(operand, Port):
        return f"(INP {operand.port})"
    return str(operand)


@dataclass
class Straight:
    """A program of assignments and ++/--, one statement a line, and the readings each
    input port gives (in the scripted device's format)."""

    statements: list[Statement] = field(default_factory=list)
    ports: dict[int, list[int]] = field(default_factory=dict)

    def source(self) -> str:
        lines = []
        for statement in self.statements:
            if isinstance(statement, Step):
                lines.append(statement.target + statement.op)
            else:
                lines.append(statement.target + "=" + render(statement.first) + "".join(
                    op + render(operand) for op, operand in statement.steps))
        return "".join(line + "\n" for line in lines)

    def sensors(self) -> dict[str, object]:
        if not self.ports:
            return {}
        # The oracle reads a used-up list's last reading again (sensors.md, "after_last").
        return {"INP": {str(port): readings for port, readings in self.ports.items()},
                "after_last": "repeat"}

    def evaluate(self) -> dict[str, int]:
        """The final value of every variable, by spec 7.2 and 7.3."""
        variables = dict.fromkeys(VARIABLES, 0)
        reads = dict.fromkeys(self.ports, 0)

        def value(operand: Operand) -> int:
            if isinstance(operand, Hex):
                return operand.value
            if isinstance(operand, Port):
                readings = self.ports.get(operand.port, [0])
                index = reads.get(operand.port, 0)
                reads[operand.port] = index + 1
                return readings[min(index, len(readings) - 1)]
            if isinstance(operand, str):
                return variables[operand]
            assert INT16_MIN <= operand <= INT16_MAX, "decimal constants are 16-bit"
            return operand

        for statement in self.statements:
            if isinstance(statement, Step):
                delta = 1 if statement.op == "++" else -1
                variables[statement.target] = wrap(variables[statement.target] + delta)
                continue
            accumulator = value(statement.first)
            for op, operand in statement.steps:
                accumulator = OPERATORS[op](accumulator, value(operand))
            variables[statement.target] = accumulator
        return variables
