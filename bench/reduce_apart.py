"""What judging each case in a process of its own costs `rl1c reduce --engine`, as it
does with an engine that could end the process it runs in (a c-ON engine): in one run,
the cases a reduction of FILE tries (with a predicate of no cost: a `(MOV` in the
program), each judged by the engines in this process (`judge`, the reference) and apart
(`judge_apart`, a fork a case): apart with nothing of the engines' loaded here, then with
the C VM's library loaded here (as `rl1c reduce` loads it, for each case to inherit),
then in this process, then apart again once this process has judged every case
(everything the engines use loaded and warm); each case N times over; cases per second
of wall time, and their ratios to judging in this process. With --batch, a batch engine
(`exec-batch:rl1c run --batch`, a process answering a job a line) beside the engines,
and how many times it was started.

    .venv/bin/python bench/reduce_apart.py [FILE.rob] [--engine NAME]... [--batch] [--rounds N]
"""

from __future__ import annotations

import argparse
import shlex
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from rl1.compiler import differential
from rl1.compiler.differential import Engine, Verdict, engine_named, judge, judge_apart
from rl1.compiler.reduce import Case, reduce
from rl1.compiler.strategies import Run
from rl1.vm.native import library, load

SAMPLE = Path(__file__).resolve().parents[1] / "examples" / "sample.rob"
RL1C = shlex.quote(str(Path(sys.executable).with_name("rl1c")))
Judging = Callable[[Run, Sequence[Engine], int], Verdict]


def tried(source: str) -> list[Case]:
    """The cases that reducing `source` while it holds a `(MOV` tries, in order."""
    cases: list[Case] = []

    def moves(case: Case) -> bool:
        cases.append(case)
        return "(MOV" in case.source

    reduce(Case(source), moves, max_tests=2000)
    return cases


def rate(judging: Judging, cases: list[Case], engines: Sequence[Engine]) -> float:
    """Cases per second that `judging` judges, in wall time."""
    started = time.perf_counter()
    for case in cases:
        judging(Run(case.source, {}), engines, 20_000)
    return len(cases) / (time.perf_counter() - started)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("file", nargs="?", default=str(SAMPLE), metavar="FILE.rob")
    parser.add_argument("--engine", action="append", metavar="NAME",
                        help="an engine (default: vm-O0 and c-O1)")
    parser.add_argument("--batch", action="store_true",
                        help="with `exec-batch:rl1c run --batch` beside the engines")
    parser.add_argument("--rounds", type=int, default=10, metavar="N",
                        help="how many times each case is judged (default 10)")
    arguments = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="rl1-bench-") as folder:
        measure(arguments.file, arguments.engine or ["vm-O0", "c-O1"], arguments.rounds,
                Path(folder) / "starts" if arguments.batch else None)


def measure(file: str, names: list[str], rounds: int, starts: Path | None) -> None:
    """Print the figures; with `starts`, a batch engine beside the engines `names`, which
    writes a byte to it each time its process starts."""
    shown = list(names)
    if starts is not None:
        names = [*names, f"exec-batch:printf . >>{shlex.quote(str(starts))}; "
                         f"exec {RL1C} run --batch"]
        shown.append("exec-batch:rl1c run --batch")
    engines = [engine for name in names if (engine := engine_named(name)) is not None]
    cases = tried(Path(file).read_text(encoding="utf-8")) * rounds
    cold = rate(judge_apart, cases, engines)
    if any(isinstance(engine, differential.CEngine) for engine in engines):
        load(library())
    loaded = rate(judge_apart, cases, engines)
    here = rate(judge, cases, engines)
    warm = rate(judge_apart, cases, engines)
    print(f"{len(cases)} cases of reducing {file} on {', '.join(shown)}: judged in this "
          f"process {here:.1f}/s; each apart {cold:.1f}/s ({cold / here:.2f}x), with the "
          f"C VM's library loaded here {loaded:.1f}/s ({loaded / here:.2f}x), with "
          f"everything warm here {warm:.1f}/s ({warm / here:.2f}x)")
    if starts is not None:
        started = len(starts.read_bytes()) if starts.exists() else 0
        print(f"the batch engine's process started {started} "
              f"time{'s' if started != 1 else ''} for the {4 * len(cases)} cases judged")


if __name__ == "__main__":
    main()
