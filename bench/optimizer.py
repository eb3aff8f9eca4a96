"""The optimizer's figures: each program of the corpus (Listing 1 and bench/corpus/)
compiled at -O2 against -O0, in the same process.

Per program and as a geometric mean over the corpus: the instructions the reference VM
executes on the program's sensor script, the code section's bytes, and the compile
time (source to .ilc bytes, the best of several). Goals: at least 30% fewer
instructions, at least 20% fewer bytes, compile time at most 2x. Every pair of runs is
also compared as spec/optimization.md says; a disagreement stops the benchmark.

    .venv/bin/python bench/optimizer.py [--level 2] [--repeat 5]
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from timing import best_time

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.differential import AstEngine, VmEngine, judge
from rl1.compiler.strategies import Run
from rl1.vm import ilc

ROOT = Path(__file__).parent.parent
CORPUS = [ROOT / "examples" / "sample.rob", *sorted((ROOT / "bench" / "corpus").glob("*.rob"))]
BUDGET = 10_000_000


def geometric_mean(ratios: list[float]) -> float:
    return math.exp(sum(map(math.log, ratios)) / len(ratios))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, default=2, help="the level set against -O0")
    parser.add_argument("--repeat", type=int, default=5, help="compiles of each; the best counts")
    options = parser.parse_args()
    level = options.level
    ratios: dict[str, list[float]] = {"instructions": [], "bytes": [], "compile": []}
    print(f"-O{level} against -O0, per program (ratio = -O{level} / -O0)")
    print(f"{'program':<16}{'instructions':>22}{'':>8}{'code bytes':>16}{'':>8}"
          f"{'compile ms':>18}{'':>8}")
    for path in CORPUS:
        source = path.read_text(encoding="utf-8")
        script = json.loads(path.with_name(path.stem + ".sensors.json").read_text("utf-8"))
        script.pop("comment", None)
        verdict = judge(Run(source, script), (AstEngine(), VmEngine(0), VmEngine(level)),
                        BUDGET)
        if verdict.problems:
            raise SystemExit(f"{path.name}: the levels disagree: {verdict.problems}")
        executed: list[float] = [verdict.observations[f"vm-O{n}"].executed or 0
                                 for n in (0, level)]
        sizes: list[float] = [len(ilc.decode(_compile(source, n)).code) for n in (0, level)]
        times = [_compile_ms(source, n, options.repeat) for n in (0, level)]
        row = f"{path.stem:<16}"
        for key, (before, now) in zip(ratios, (executed, sizes, times), strict=True):
            ratios[key].append(now / before)
            figures = (f"{before:.2f} -> {now:.2f}" if key == "compile"
                       else f"{before:.0f} -> {now:.0f}")
            row += f"{figures:>22}{now / before:>8.2f}"
        print(row)
    means = {key: geometric_mean(values) for key, values in ratios.items()}
    print(f"geometric mean over {len(CORPUS)} programs: "
          f"instructions x{means['instructions']:.2f} "
          f"({1 - means['instructions']:.0%} fewer, goal >= 30%), "
          f"code bytes x{means['bytes']:.2f} ({1 - means['bytes']:.0%} fewer, goal >= 20%), "
          f"compile time x{means['compile']:.2f} (goal <= 2)")


def _compile_ms(source: str, level: int, repeat: int) -> float:
    return best_time(lambda: _compile(source, level), repeat) * 1000


def _compile(source: str, level: int) -> bytes:
    output = compile_text(source, "bench.rob", level=level).output
    assert output is not None
    return output


if __name__ == "__main__":
    main()
