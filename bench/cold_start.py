"""Cold start: `rl1c check` on the sample as a whole process, against
`python3 -c "import click"` in the same run, the floor of any click command (goal: at
most 1.5x); `python3 -c pass` is printed for information. Interleaves the commands so
that all see the same machine load, and reports medians.

`python3` is the interpreter running this script, the virtual environment's, as in a
shell where .venv is activated: every process starts the same interpreter with the same
site-packages. In the editable development install that start-up already imports re,
enum and pathlib (for setuptools' import hook); after a regular `pip install` every
process starts faster, and click and rl1c pay for those themselves.

It first byte-compiles the project's modules, as pip does for a package it installs:
an editable install leaves that to the first run, which cannot do it where
PYTHONDONTWRITEBYTECODE is set (as on our development machine), so every start would
compile all of rl1 again.

With `--instructions` it also counts the instructions each command executes under
`valgrind --tool=callgrind`: a figure that does not depend on the machine's load.

    .venv/bin/python bench/cold_start.py [--runs 15] [--instructions]
"""

from __future__ import annotations

import argparse
import compileall
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_seconds(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def instructions(command: list[str]) -> int:
    """The instructions `command` executes, counted by callgrind."""
    with tempfile.TemporaryDirectory() as folder:
        result = subprocess.run(["valgrind", "--tool=callgrind",
                                 f"--callgrind-out-file={folder}/out", *command],
                                capture_output=True, text=True, check=False)
    found = re.search(r"Collected : (\d+)", result.stderr)
    if found is None:
        raise SystemExit(f"callgrind gave no count:\n{result.stderr}")
    return int(found.group(1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15)
    parser.add_argument("--instructions", action="store_true",
                        help="also count instructions with valgrind's callgrind")
    options = parser.parse_args()
    for package in ("compiler", "vm", "lsp"):
        compileall.compile_dir(ROOT / package, quiet=1)
    rl1c = str(Path(sys.executable).with_name("rl1c"))
    commands = {
        "rl1c check sample.rob": [rl1c, "check", str(ROOT / "examples" / "sample.rob")],
        'python3 -c "import click"': [sys.executable, "-c", "import click"],
        "python3 -c pass": [sys.executable, "-c", "pass"],
    }
    for command in commands.values():
        run_seconds(command)  # warms the OS page cache
    seconds: dict[str, list[float]] = {name: [] for name in commands}
    for _ in range(options.runs):
        for name, command in commands.items():
            seconds[name].append(run_seconds(command))
    medians = {name: statistics.median(times) * 1000 for name, times in seconds.items()}
    width = max(map(len, commands))
    for name, median in medians.items():
        print(f"{name:<{width}}: {median:.1f} ms (median of {options.runs})")
    check, click = medians["rl1c check sample.rob"], medians['python3 -c "import click"']
    print(f"ratio rl1c check / import click: {check / click:.2f}x (goal <= 1.5x)")
    if options.instructions:
        counts = {name: instructions(command) for name, command in commands.items()}
        for name, count in counts.items():
            print(f"{name:<{width}}: {count / 1e6:.1f} M instructions")
        ratio = counts["rl1c check sample.rob"] / counts['python3 -c "import click"']
        print(f"ratio in instructions: {ratio:.2f}x (goal <= 1.5x)")


if __name__ == "__main__":
    main()
