"""Record: the front end's value classes compare, hash and print by their fields."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.record import Record


class Pair(Record):
    __slots__ = ("left", "right")

    def __init__(self, left: object, right: object) -> None:
        self.left = left
        self.right = right


class Labelled(Pair):
    __slots__ = ("label",)

    def __init__(self, left: object, right: object, label: str) -> None:
        super().__init__(left, right)
        self.label = label


class Single(Record):
    __slots__ = ("only",)

    def __init__(self, only: object) -> None:
        self.only = only


class Empty(Record):
    __slots__ = ()


values = st.integers(-3, 3) | st.text(max_size=2) | st.none()


def test_fields_are_the_slots_base_first() -> None:
    assert Pair.fields == ("left", "right")
    assert Labelled.fields == ("left", "right", "label")
    assert Labelled(1, 2, "x").values() == (1, 2, "x")
    assert Single(5).values() == (5,)
    assert Empty().values() == ()


@given(values, values, values, values)
def test_equal_and_hashed_by_value(a: object, b: object, c: object, d: object) -> None:
    assert (Pair(a, b) == Pair(c, d)) == ((a, b) == (c, d))
    if Pair(a, b) == Pair(c, d):
        assert hash(Pair(a, b)) == hash(Pair(c, d))
    assert Single(a) == Single(a) and hash(Single(a)) == hash(Single(a))


def test_a_record_equals_only_records_of_its_own_class() -> None:
    assert Pair(1, 2) != Labelled(1, 2, "") and Labelled(1, 2, "") != Pair(1, 2)
    assert Pair(1, 2) != (1, 2)
    assert Empty() == Empty() and Empty() != Single(None)
    span = ast.Span(1, 1, 1, 2)
    selector: object = ast.Selector(span, "A")
    assert ast.Var(span, "A") != selector  # same values, other meaning


def test_repr_names_every_field() -> None:
    assert repr(Labelled(1, "a", "x")) == "Labelled(left=1, right='a', label='x')"
    assert repr(Empty()) == "Empty()"
