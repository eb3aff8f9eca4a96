"""`rl1c test`'s memory does not grow with the tests of a file: 2,000 failing tests on a
world once took 500 MB (each failure kept its run's device and trace for the report,
and the front end moved each test's garbage cycles where only a full collection frees
them); a test file of 1 MiB holds some 12,000 tests."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from rl1.compiler.cli.project_template import FILES

pytestmark = pytest.mark.slow  # some 500 simulated runs, in two processes

MEASURED = """
import resource, sys
from rl1.compiler.cli.main import rl1c
try:
    rl1c(sys.argv[1:])
except SystemExit as end:
    print(end.code, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr)
"""
"""`rl1c` in a process that says, last on standard error, its exit status and its peak
resident memory (KiB)."""
GROWTH_BOUND_MIB = 30
"""What 300 more failing tests may add to the peak: less than half of what they added
(66 MiB) when every failure was kept."""


def peak_mib_of_failing_tests(folder: Path, count: int) -> float:
    """The peak resident memory of `rl1c test` on `count` failing tests on a world."""
    for name in ("main.rob", "main.world.toml"):
        (folder / name).write_text(FILES[name], encoding="utf-8")
    tests = folder / f"many{count}.tests.toml"
    tests.write_text("".join(
        f'[[test]]\nname = "t{i}"\nprogram = "main.rob"\nworld = "main.world.toml"\n'
        "expect.variables = { A = 5 }\n" for i in range(count)), encoding="utf-8")
    done = subprocess.run([sys.executable, "-c", MEASURED, "test", str(tests), "--jobs", "1"],
                          timeout=900, capture_output=True, text=True, check=False)
    assert f"{count} failed" in done.stdout, done.stderr[-500:]
    status, peak = done.stderr.split()[-2:]
    assert status == "1"
    return int(peak) / 1024


def test_memory_does_not_grow_with_the_failing_tests(tmp_path: Path) -> None:
    few = peak_mib_of_failing_tests(tmp_path, 100)
    many = peak_mib_of_failing_tests(tmp_path, 400)
    assert many - few < GROWTH_BOUND_MIB, (few, many)
