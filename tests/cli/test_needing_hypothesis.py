"""cli/fuzz.py's needing_hypothesis: what rl1c fuzz and rl1c reduce --engine say when
the optional Hypothesis is missing, and only then."""

from __future__ import annotations

import pytest

from rl1.compiler.cli.command import Failure
from rl1.compiler.cli.fuzz import needing_hypothesis


@pytest.mark.parametrize("missing", ["hypothesis", "hypothesis.strategies"])
def test_hypothesis_missing_is_said_with_how_to_install_it(missing: str) -> None:
    with pytest.raises(Failure) as said, needing_hypothesis("rl1c x compares", ", or not"):
        raise ModuleNotFoundError(f"No module named {missing!r}", name=missing)
    assert str(said.value) == (
        "rl1c x compares with Hypothesis, an optional part of rl1 that is not "
        "installed here; install it with `pip install 'rl1[fuzz]'`, or not")
    assert said.value.status == 2


@pytest.mark.parametrize("missing", ["hypothesis_extra", "numpy", None])
def test_another_missing_module_is_not_taken_for_hypothesis(missing: str | None) -> None:
    with pytest.raises(ModuleNotFoundError), needing_hypothesis("rl1c x", ""):
        raise ModuleNotFoundError("No module", name=missing)
