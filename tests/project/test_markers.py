"""The markers `make quick` leaves out: registered in pyproject.toml, applied in
tests/support/markers.py to every Hypothesis property and by path to places that exist, and
every one of them left out by the Makefile's quick target."""

from __future__ import annotations

import re
import tomllib
from types import SimpleNamespace

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support import ROOT, markers

PYTEST = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))[
    "tool"]["pytest"]["ini_options"]
REGISTERED = {line.split(":", 1)[0] for line in PYTEST["markers"]}




@pytest.mark.parametrize("where", list(markers.MARKS))
def test_every_place_marked_exists(where: str) -> None:
    path, _, test = where.partition("::")
    assert (ROOT / path).exists(), f"support/markers.py marks {path}, which does not exist"
    if test:
        source = (ROOT / path).read_text(encoding="utf-8")
        assert re.search(rf"^(?:async )?def {re.escape(test)}\(", source, re.MULTILINE), (
            f"support/markers.py marks {where}, which {path} does not define")


def test_every_mark_given_is_registered() -> None:
    given = {mark for marks in markers.MARKS.values() for mark in marks}
    assert given <= REGISTERED


@pytest.mark.parametrize(("nodeid", "marks"), [
    ("tests/c/test_c_vm.py::test_vector[calls-3]", {"needs_cc", "slow"}),
    ("tests/backend/test_firmware.py::test_the_c_array_compiles_and_holds_the_ilc_bytes[x]",
     {"needs_cc"}),
    ("tests/backend/test_firmware.py::test_names_c_cannot_take_are_refused", set()),
    ("tests/cli/test_cli_check.py::test_something", set()),
])
def test_a_test_gets_the_marks_of_its_folder_module_and_name(nodeid: str,
                                                             marks: set[str]) -> None:
    assert set(markers.marks_of(nodeid)) == marks


@given(st.integers())
def _a_property(number: int) -> None:
    assert number == number


def _an_example() -> None:
    assert 1 + 1 == 2


def test_every_property_is_slow_and_an_example_is_not() -> None:
    assert markers.is_property(SimpleNamespace(obj=_a_property))
    assert not markers.is_property(SimpleNamespace(obj=_an_example))
    assert not markers.is_property(SimpleNamespace())  # an item of no function


def test_make_quick_leaves_out_every_marker_and_make_test_none() -> None:
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    quick = re.search(r"^QUICK := (.*)$", makefile, re.MULTILINE)
    assert quick is not None, "the Makefile has no QUICK expression"
    assert re.fullmatch(r"not \w+(?: and not \w+)*", quick[1])
    assert set(re.findall(r"not (\w+)", quick[1])) == REGISTERED
    pytest_rule = re.search(r"^pytest:.*\n\t(.*)$", makefile, re.MULTILINE)
    assert pytest_rule is not None and "-m" not in pytest_rule[1].split()
