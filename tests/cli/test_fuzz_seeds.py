"""`rl1c fuzz --seed N` gives the same programs whatever else a process has loaded.

Hypothesis (6.131 on) draws some literals from the source of the modules a process has
loaded, so without compiler.fuzz.only_hypothesis_constants a seed gave other programs
in a Dask worker, with rl1 installed as a wheel, or in a command importing more. Each
campaign runs in a fresh interpreter: what Hypothesis has collected lasts a process."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from support import ROOT
from support.recording import recorded

pytestmark = pytest.mark.slow  # two campaigns, each in an interpreter of its own

# Programs of each campaign: without only_hypothesis_constants, the two part at their
# 7th program (as they did with 150), each program drawing some 540 choices.
PROGRAMS = 50

CAMPAIGN = f"""
import sys
from rl1.compiler import fuzz
from rl1.compiler.differential import VmEngine
from support.recording import Recording
if sys.argv[2] == "more":
    import more_literals  # a module of this machine's, with literals of its own
fuzz.campaign([Recording(__import__("pathlib").Path(sys.argv[1])), VmEngine(1)], 20_000,
              count={PROGRAMS}, seconds=None, seed=20261126, progress=lambda *_: None)
"""

MORE_LITERALS = ("NUMBERS = (12345, 31337, -7777, 4242, 999, 32767, -32768, 17)\n"
                 "TEXTS = ('A=B+C', ':10', '#20', '(MOV 3,3)')\n")


def _programs(tmp_path: Path, loaded: str) -> list[str]:
    path = tmp_path / f"{loaded}.jsonl"
    environment = {**os.environ,
                   "PYTHONPATH": os.pathsep.join([str(ROOT / "tests"), str(tmp_path)])}
    subprocess.run([sys.executable, "-c", CAMPAIGN, str(path), loaded], check=True,
                   env=environment, cwd=tmp_path, timeout=600)
    return recorded(path)


def test_a_seed_gives_the_same_programs_with_other_modules_loaded(tmp_path: Path) -> None:
    (tmp_path / "more_literals.py").write_text(MORE_LITERALS, encoding="utf-8")
    alone = _programs(tmp_path, "alone")
    with_more = _programs(tmp_path, "more")
    assert len(alone) >= PROGRAMS
    assert with_more == alone
