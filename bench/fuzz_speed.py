"""`rl1c fuzz` speed, in one run: programs per second of a campaign comparing the -O0
reference VM with one more engine, in this process (compiler/fuzz.py's `campaign`, one
process, the same seed and programs for each):

- built in: `vm-O2`;
- `exec:`: `rl1c run` started for every program (a process, Python's start-up and the
  imports each time);
- `exec-batch:`: `rl1c run --batch`, started once, a job a line (spec/optimization.md,
  section 5, "Batch engines");
- and, for scale, the default engines (ast, vm-O0, vm-O1, vm-O2) on every core.

Each figure is also given as a ratio to the built-in one.

    .venv/bin/python bench/fuzz_speed.py [--count N]
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys
import time
from pathlib import Path

from rl1.compiler import fuzz
from rl1.compiler.differential import DEFAULT_ENGINES, Engine, engine_named
from rl1.compiler.executors import workers

RL1C = shlex.quote(str(Path(sys.executable).with_name("rl1c")))
BUDGET = 20_000
SEED = 1
ENGINES = {
    "built in (vm-O2)": "vm-O2",
    "exec: (rl1c run, a process a program)":
        f"exec:{RL1C} run {{ilc}} --sensors {{sensors}} --budget {{budget}} --format json",
    "exec-batch: (rl1c run --batch, one process)": f"exec-batch:{RL1C} run --batch",
}


def named(name: str) -> Engine:
    engine = engine_named(name)
    assert engine is not None, name
    return engine


def rate(engines: list[Engine], count: int, jobs: int = 1) -> float:
    """Programs per second of a campaign of `count` programs on `jobs` processes."""
    started = time.perf_counter()
    with workers(jobs) as held:
        outcome = fuzz.campaign(engines, BUDGET, count=count, seconds=None, seed=SEED,
                                progress=lambda *_: None,
                                executor=held.executor, jobs=max(held.slots, 1))
    assert outcome.finding is None, outcome.finding
    return outcome.programs / (time.perf_counter() - started)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=200, help="programs per campaign")
    count = parser.parse_args().count
    reference = named("vm-O0")
    figures = {label: rate([reference, named(name)], count) for label, name in ENGINES.items()}
    built_in = figures["built in (vm-O2)"]
    print(f"rl1c fuzz, {count} programs, seed {SEED}, vm-O0 against each engine, one process:")
    for label, figure in figures.items():
        print(f"  {label:<48} {figure:7.1f} programs/s  ({figure / built_in:5.2f}x built in)")
    cores = os.cpu_count() or 1
    default = [named(name) for name in DEFAULT_ENGINES]
    one, every = rate(default, count), rate(default, count, cores)
    print(f"default engines ({', '.join(DEFAULT_ENGINES)}): {one:.1f} programs/s in one "
          f"process, {every:.1f} on {cores} ({every / one:.2f}x)")


if __name__ == "__main__":
    main()
