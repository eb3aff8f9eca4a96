"""When the server checks a change: a change alone at once, a burst after a short wait
(the burst's coalescing itself is tested over stdio in test_diagnostics.py)."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rl1.lsp.checking import BURST_SECONDS, wait_before_check


@given(st.floats(0, 1e6))
def test_the_first_change_of_a_document_is_checked_at_once(now: float) -> None:
    assert wait_before_check(None, now) == 0.0


@pytest.mark.parametrize("gap", [0.0, BURST_SECONDS / 5, BURST_SECONDS * 0.9])
def test_a_change_close_behind_another_waits_for_the_burst_to_end(gap: float) -> None:
    assert wait_before_check(100.0, 100.0 + gap) == BURST_SECONDS


@pytest.mark.parametrize("gap", [BURST_SECONDS * 1.1, 0.1, 5.0])
def test_a_change_after_a_pause_is_checked_at_once(gap: float) -> None:
    assert wait_before_check(100.0, 100.0 + gap) == 0.0
