"""optimize's `fired`: the passes that changed the program, -O2's final passes among
them (`rl1c fuzz --format json` counts them), and none that changed nothing."""

from __future__ import annotations

import pytest

from rl1.compiler.analysis import analyze
from rl1.compiler.backend import optimize
from rl1.compiler.backend.lower import lower


def fired_at(source: str, level: int) -> list[str]:
    fired: list[str] = []
    optimize.optimize(lower(analyze(source).program), level, fired=fired.append)
    return fired


@pytest.mark.parametrize(("source", "fired"), [
    # a counted loop: its decrement and branch fused; it ends on that branch, no END
    ("S=4\n:10 (MVI S,S,150); (ROT 90)\nS--; ?S>#10\n", ["fuse"]),
    # a call, then the end: left out (final_end.py); nothing to fuse
    ("(HLD)\n", ["leave_out_final_end"]),
    ("", []),
])
def test_the_final_passes_are_told_when_they_change_the_program(source: str,
                                                                  fired: list[str]) -> None:
    assert fired_at(source, 2) == fired


def test_level_1_runs_no_final_pass() -> None:
    assert fired_at("S=4\n:10 (MVI S,S,150); (ROT 90)\nS--; ?S>#10\n(HLD)\n", 1) == []
