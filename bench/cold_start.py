"""Cold start: `rl1c check` on the sample as a whole process, against `python3 -c pass`
in the same run (goal: at most 2x). Interleaves the two commands so that both see the
same machine load, and reports medians.

`python3` is the interpreter running this script, the virtual environment's, as in a
shell where .venv is activated: both processes start the same interpreter with the same
site-packages. In the editable development install that start-up already imports re,
enum and pathlib (for setuptools' import hook), and `rl1c check` needs the first two;
after a regular `pip install` both start faster and rl1c pays for re and enum itself,
so the ratio there is larger (see the issue's closing notes for the figures).

It first byte-compiles the project's modules, as pip does for a package it installs:
an editable install leaves that to the first run, which cannot do it where
PYTHONDONTWRITEBYTECODE is set (as on our development machine), so every start would
compile all of rl1 again.

    .venv/bin/python bench/cold_start.py [--runs 15]
"""

from __future__ import annotations

import argparse
import compileall
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_seconds(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15)
    options = parser.parse_args()
    for package in ("compiler", "vm", "lsp"):
        compileall.compile_dir(ROOT / package, quiet=1)
    rl1c = str(Path(sys.executable).with_name("rl1c"))
    check = [rl1c, "check", str(ROOT / "examples" / "sample.rob")]
    baseline = [sys.executable, "-c", "pass"]
    run_seconds(check)  # warms the OS page cache
    checks, passes = [], []
    for _ in range(options.runs):
        checks.append(run_seconds(check))
        passes.append(run_seconds(baseline))
    check_ms, pass_ms = statistics.median(checks) * 1000, statistics.median(passes) * 1000
    print(f"rl1c check sample.rob: {check_ms:.1f} ms (median of {options.runs})")
    print(f"python3 -c pass      : {pass_ms:.1f} ms (median of {options.runs})")
    print(f"ratio: {check_ms / pass_ms:.1f}x (goal <= 2x)")


if __name__ == "__main__":
    main()
