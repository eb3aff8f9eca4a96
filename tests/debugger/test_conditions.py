"""A breakpoint's condition: a value written as the language writes one, compared with 0
as a conditional jump compares it (`?A<` is A<0), read by the front end's parser and
computed by the interpreter's arithmetic; and what the session refuses, in words."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rl1.compiler.debugger import DebugError, parse_call, parse_condition, parse_value
from rl1.vm.language import VARIABLE_INDEX, VARIABLES

values = st.integers(-32768, 32767)


def _variables(**named: int) -> list[int]:
    variables = [0] * len(VARIABLES)
    for name, value in named.items():
        variables[VARIABLE_INDEX[name]] = value
    return variables


def _wrapped(value: int) -> int:
    return (value + 2**15) % 2**16 - 2**15


@pytest.mark.parametrize(("text", "negative", "zero", "positive"), [
    ("A<0", True, False, False), ("A=0", False, True, False), ("A>0", False, False, True),
    (" A < 0 ", True, False, False)])
def test_a_variable_against_0_is_the_conditional_jumps_test(
        text: str, negative: bool, zero: bool, positive: bool) -> None:
    condition = parse_condition(text)
    assert [condition.met(_variables(A=value)) for value in (-1, 0, 1)] == [
        negative, zero, positive]


@given(values, values)
def test_a_difference_wraps_on_16_bits_as_the_program_computes_it(a: int, b: int) -> None:
    condition = parse_condition("U-L>0")
    assert condition.met(_variables(U=a, L=b)) == (_wrapped(a - b) > 0)


@given(values, values)
def test_a_value_is_read_left_to_right_with_shifts_and_constants(a: int, c: int) -> None:
    # Listing 1's own expression: a<3 shifts a left by 3, then +c, then >a shifts right.
    condition = parse_condition("a<3+c-$10=0")
    expected = _wrapped(_wrapped(_wrapped(a * 8) + c) - 16)
    assert condition.met(_variables(a=a, c=c)) == (expected == 0)


@pytest.mark.parametrize(("text", "says"), [
    ("A", "compares nothing with 0"),
    ("A<5", "compares with 5, and a condition compares with 0 (`<` after a value is a "
            "shift): write `A-5<0`"),
    ("U-L>-20", "write `U-L+20>0`"),
    ("<0", "compares nothing with 0"),
    ("A+<0", "the value `A+` cannot be read"),
    ("A; B<0", "the value `A; B` cannot be read"),
    ("(IMG)-180<0", "calls a built-in"),
    ("A-40000<0", "the constant 40000 in `A-40000` is outside -32768..32767"),
])
def test_what_is_no_condition_is_said_with_what_to_write(text: str, says: str) -> None:
    with pytest.raises(DebugError) as raised:
        parse_condition(text)
    assert says in str(raised.value)
    if "compares nothing" in says or "cannot be read" in says:  # and how to write one
        assert "`A<0`, `U-L>0`, `d=0`" in str(raised.value)


@pytest.mark.parametrize(("name", "form"), [
    ("IMG", ("IMG", None)), ("img", ("IMG", None)), ("CAM", ("CAM", None)),
    ("cam p", ("CAM", "P")), ("ULT A", ("ULT", "A"))])
def test_a_call_breakpoint_names_a_built_in_or_one_of_its_forms(
        name: str, form: tuple[str, str | None]) -> None:
    assert parse_call(name) == form


@pytest.mark.parametrize(("name", "says"), [
    ("IMAGE", "no built-in to stop at"), ("END", "no built-in to stop at"),
    ("CAM Q", "its forms are Z, U, D, A, P, R"), ("IMG A", "write `IMG` alone")])
def test_an_unknown_call_is_refused_with_what_exists(name: str, says: str) -> None:
    with pytest.raises(DebugError, match=says):
        parse_call(name)


@given(values, values)
def test_a_value_is_what_the_condition_compares(a: int, c: int) -> None:
    value = parse_value(" a<3+c-$10 ")
    assert value.text == "a<3+c-$10"
    assert value.of(_variables(a=a, c=c)) == _wrapped(_wrapped(_wrapped(a * 8) + c) - 16)


@pytest.mark.parametrize(("text", "says"), [
    (" ", "no value is given: write variables and constants joined by operators, as "
          "`U-L` or `a<3+c`"),
    ("x+(IMG)", "`x+(IMG)` calls a built-in, which would drive the vehicle"),
    ("#10", "the value `#10` cannot be read")])
def test_what_is_no_value_is_said(text: str, says: str) -> None:
    with pytest.raises(DebugError) as raised:
        parse_value(text)
    assert str(raised.value).startswith(says)
