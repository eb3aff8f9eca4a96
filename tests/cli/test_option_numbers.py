"""The whole-number options of rl1c (cli/command.py): `at_least_one`, `a_budget`, and
`or_none`, which lets either be left out."""

from __future__ import annotations

import click
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rl1.compiler.cli.command import a_budget, at_least_one, or_none
from rl1.vm.faults import MAX_BUDGET

CONTEXT = click.Context(click.Command("rl1c"))
OPTION = click.Option(["--n"])


@given(st.one_of(st.integers(-10, MAX_BUDGET + 10).map(str),
                 st.integers(MAX_BUDGET - 2, MAX_BUDGET + 2).map(str), st.text(max_size=8)))
def test_each_takes_exactly_the_whole_numbers_in_its_range(value: str) -> None:
    try:
        number: int | None = int(value)
    except ValueError:
        number = None
    for callback, most, expected in ((at_least_one, None, "of at least 1"),
                                     (a_budget, MAX_BUDGET, f"from 1 to {MAX_BUDGET}")):
        if number is not None and number >= 1 and (most is None or number <= most):
            assert callback(CONTEXT, OPTION, value) == number
        else:
            with pytest.raises(click.BadParameter) as refused:
                callback(CONTEXT, OPTION, value)
            assert refused.value.message == f"expected a whole number {expected}, got {value!r}"


def test_or_none_leaves_an_option_left_out_as_none_and_checks_one_given() -> None:
    assert or_none(at_least_one)(CONTEXT, OPTION, None) is None
    assert or_none(a_budget)(CONTEXT, OPTION, "7") == 7
    with pytest.raises(click.BadParameter, match="expected a whole number of at least 1"):
        or_none(at_least_one)(CONTEXT, OPTION, "0")
