"""What judging each program in a process of its own costs `rl1c fuzz`: the searches
lost with a worker that died run again so (differential.judge_apart, a fork a program),
so that the program that ended it is named. In one run, the same seeded search of N
programs on the default engines, judged in this process (`judge`, the reference) and
apart; programs per second of wall time (a fork's cost is mostly the child's, which
this process's CPU time leaves out), and their ratio.

    .venv/bin/python bench/fuzz_apart.py [--count 100] [--engine NAME]...
"""

from __future__ import annotations

import argparse
import time

from rl1.compiler import fuzz
from rl1.compiler.differential import DEFAULT_ENGINES, engine_named


def rate(task: fuzz.Search) -> float:
    """Programs per second that `search(task)` judges, in wall time."""
    started = time.perf_counter()
    searched = fuzz.search(task)
    assert not searched.findings, "the engines disagree: measure agreeing ones"
    return searched.programs / (time.perf_counter() - started)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=100, help="programs of the search")
    parser.add_argument("--engine", action="append", metavar="NAME",
                        help="an engine (default: those of rl1c fuzz)")
    arguments = parser.parse_args()
    engines = tuple(engine for name in arguments.engine or DEFAULT_ENGINES
                    if (engine := engine_named(name)) is not None)
    task = fuzz.Search(0, 7, arguments.count, engines, 20_000)
    rate(task)  # the generator's and the engines' first use, left out of the figures
    here = rate(task)
    apart = rate(fuzz.Search(0, 7, arguments.count, engines, 20_000, apart=True))
    print(f"{arguments.count} programs on {', '.join(engine.name for engine in engines)}:"
          f" judged in this process {here:.1f}/s, each apart {apart:.1f}/s "
          f"({apart / here:.2f}x)")


if __name__ == "__main__":
    main()
