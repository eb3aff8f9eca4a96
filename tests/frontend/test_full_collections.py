"""frontend/collector.py's FullCollections: a full collection every so many calls, which
a campaign's worker and `rl1c test` count their runs with."""

from __future__ import annotations

import gc

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rl1.compiler.frontend.collector import FullCollections


@given(every=st.integers(1, 20), calls=st.integers(0, 100))
def test_it_collects_once_every_so_many_calls(every: int, calls: int) -> None:
    collected = []
    collections = FullCollections(every)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(gc, "collect", lambda: collected.append(1))
        for _ in range(calls):
            collections.count()
    assert len(collected) == calls // every

