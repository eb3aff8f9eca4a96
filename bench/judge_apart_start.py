"""What `judge_apart` costs a case when it cannot fork: in a process of several threads
(a Dask worker, whose tasks run beside its event loop), where it spawns a new Python
process instead (differential.forks_safely). In one run, the same cases of
examples/sample.rob on the default engines judged in this process (`judge`, the
reference), apart from the main thread of a process of one thread (a fork a case), and
apart from a thread of a process of two (a spawned process a case); cases per second of
wall time, and their ratios to judging in this process.

    .venv/bin/python bench/judge_apart_start.py [--cases N]
"""

from __future__ import annotations

import argparse
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from rl1.compiler.differential import (
    DEFAULT_ENGINES,
    Engine,
    Verdict,
    engine_named,
    forks_safely,
    judge,
    judge_apart,
)
from rl1.compiler.strategies import Run

SAMPLE = Path(__file__).resolve().parents[1] / "examples" / "sample.rob"
Judging = Callable[[Run, Sequence[Engine], int], Verdict]


def rate(judging: Judging, cases: list[Run], engines: Sequence[Engine]) -> float:
    """Cases judged a second of wall time."""
    started = time.perf_counter()
    for case in cases:
        judging(case, engines, 20_000)
    return len(cases) / (time.perf_counter() - started)


def in_a_thread(judging: Judging, cases: list[Run], engines: Sequence[Engine]) -> float:
    """`rate` measured in a thread of its own, the main thread waiting for it."""
    rates: list[float] = []
    thread = threading.Thread(target=lambda: rates.append(rate(judging, cases, engines)))
    thread.start()
    thread.join()
    return rates[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=20)
    cases = [Run(SAMPLE.read_text(encoding="utf-8"), {})] * parser.parse_args().cases
    engines = [engine for name in DEFAULT_ENGINES if (engine := engine_named(name))]
    assert forks_safely(), "this process runs threads already"
    here = rate(judge, cases, engines)
    forked = rate(judge_apart, cases, engines)
    spawned = in_a_thread(judge_apart, cases, engines)
    print(f"{len(cases)} cases of {SAMPLE.name} on {', '.join(e.name for e in engines)}")
    print(f"  in this process          {here:7.1f} cases/s  1.00x")
    print(f"  apart, forked            {forked:7.1f} cases/s  {forked / here:.2f}x")
    print(f"  apart, spawned (thread)  {spawned:7.1f} cases/s  {spawned / here:.2f}x")


if __name__ == "__main__":
    main()
