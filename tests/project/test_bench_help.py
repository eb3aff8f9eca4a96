"""Every benchmark script says what it measures and how to call it when asked with
`--help`, and exits 0, rather than starting a run of minutes (or failing with a
traceback, as bench/studio_latency.py did, taking `--help` for its count of runs)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench"
SCRIPTS = [path for path in sorted(BENCH.glob("*.py"))
           if 'if __name__ == "__main__":' in path.read_text(encoding="utf-8")]


def test_there_are_scripts_to_ask() -> None:
    assert len(SCRIPTS) > 20


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda path: path.name)
def test_help_says_how_to_run_it_and_runs_nothing(script: Path) -> None:
    shown = subprocess.run([sys.executable, script, "--help"], capture_output=True, text=True,
                           timeout=120, cwd=BENCH)
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout.startswith("usage:"), shown.stdout
    assert "Traceback" not in shown.stderr
