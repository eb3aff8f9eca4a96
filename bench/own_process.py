"""What a process of its own costs the work of `rl1c fuzz` where it cannot fork: in a
process of several threads (a Dask worker, whose tasks run beside its event loop). In
one run: the same cases of examples/sample.rob on the default engines judged in this
process (`judge`, the reference), apart from the main thread of a process of one thread
(`judge_apart`, a fork a case), and apart from a thread of a process of two (a spawned
process a case: differential.forks_safely), in cases per second of wall time and their
ratios to judging in this process; then a search of `rl1c fuzz` (100 programs) in this
process and in a process spawned for it, as a cluster's worker runs each
(executors.in_own_process: the first search starts that process, the next finds it),
in seconds and their ratios.

    .venv/bin/python bench/own_process.py [--cases N]
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
from rl1.compiler.executors import in_own_process
from rl1.compiler.fuzz import BATCH, Search, Searched, search
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
    task = Search(0, 1, BATCH, tuple(engines), 20_000)
    print(f"a search of {BATCH} programs on them")
    reference = 0.0  # the seconds of the search in this process
    for where, searching in [("in this process", search),
                             ("in a process of its own, started", own),
                             ("in that process again", own)]:
        started = time.perf_counter()
        searching(task)
        seconds = time.perf_counter() - started
        reference = reference or seconds
        print(f"  {where:34} {seconds:6.2f} s  {seconds / reference:.2f}x")


def own(task: Search) -> Searched:
    """The search `task` in this thread's process of its own, as a cluster's worker
    makes it."""
    return in_own_process((), search, task)


if __name__ == "__main__":
    main()
