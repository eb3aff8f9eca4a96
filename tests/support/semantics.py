"""The spec's 16-bit arithmetic written as a test oracle, differently from both engines:
modulo and floor division instead of masks and shifts."""

from __future__ import annotations


def int16(value: int) -> int:
    value %= 65536
    return value - 65536 if value >= 32768 else value


def shifted(value: int, count: int, left: bool) -> int:
    """`value < count` (left) or `value > count`: a negative count shifts the other way,
    a count of 16 or more shifts every bit out."""
    if count < 0:
        count, left = -count, not left
    factor: int = 2 ** min(count, 16)
    return int16(value * factor) if left else value // factor


def operate(op: str, left: int, right: int) -> int:
    if op in "<>":
        return shifted(left, right, op == "<")
    return int16({"+": left + right, "-": left - right, "&": left & right,
                  "|": left | right, "^": left ^ right}[op])
