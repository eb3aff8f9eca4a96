"""The optimizer's figures: each program of two sets compiled at -O2 (or -O1) against
-O0, in the same process. The corpus (Listing 1 and bench/corpus/) is what the passes
were tuned on; bench/unseen/ was written apart from them (issue 25), to tell a pass that
generalizes from one that fits the corpus.

Per program and as a geometric mean over each set: the instructions the reference VM
executes on the program's sensor script, the code section's bytes, and the compile
time (source to .ilc bytes, the best of several). Goals (issue 25): -O2 at least 40%
fewer instructions and 30% fewer bytes, -O1 at least 15% fewer instructions, compile
time at most 2x. Every pair of runs is also compared as spec/optimization.md says; a
disagreement stops the benchmark. With --profile, where the level's code bytes and
executed instructions go in each set, by opcode: what a pass to come would have to take.

    .venv/bin/python bench/optimizer.py [--level 2] [--set corpus|unseen] [--repeat 5]
                                        [--profile]
"""

from __future__ import annotations

import argparse
import json
import math
from collections import Counter
from pathlib import Path

from timing import best_time

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.differential import AstEngine, VmEngine, judge
from rl1.compiler.strategies import Run
from rl1.vm import ilc
from rl1.vm.verifier import verify

ROOT = Path(__file__).parent.parent
SETS = {
    "corpus": [ROOT / "examples" / "sample.rob",
               *sorted((ROOT / "bench" / "corpus").glob("*.rob"))],
    "unseen": sorted((ROOT / "bench" / "unseen").glob("*.rob")),
}
# The goals of issue 25 for each level: fewer instructions executed, fewer code bytes.
GOALS = {1: (0.15, 0.0), 2: (0.40, 0.30)}
BUDGET = 10_000_000


def geometric_mean(ratios: list[float]) -> float:
    return math.exp(sum(map(math.log, ratios)) / len(ratios))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, choices=(1, 2), default=2,
                        help="the level set against -O0: 1 or 2 (default 2)")
    parser.add_argument("--repeat", type=int, default=5, help="compiles of each; the best counts")
    parser.add_argument("--set", choices=sorted(SETS), action="append",
                        help="the set measured (repeatable; both when left out)")
    parser.add_argument("--profile", action="store_true",
                        help="also the level's code bytes and executed instructions by opcode")
    options = parser.parse_args()
    for name in options.set or sorted(SETS):
        measure(name, SETS[name], options.level, options.repeat, options.profile)


def measure(name: str, programs: list[Path], level: int, repeat: int, profile: bool) -> None:
    ratios: dict[str, list[float]] = {"instructions": [], "bytes": [], "compile": []}
    code_bytes: Counter[str] = Counter()  # by opcode, over the set's code at `level`
    executed_by_opcode: Counter[str] = Counter()
    print(f"{name}: -O{level} against -O0, per program (ratio = -O{level} / -O0)")
    print(f"{'program':<16}{'instructions':>22}{'':>8}{'code bytes':>16}{'':>8}"
          f"{'compile ms':>18}{'':>8}")
    for path in programs:
        source = path.read_text(encoding="utf-8")
        script = json.loads(path.with_name(path.stem + ".sensors.json").read_text("utf-8"))
        script.pop("comment", None)
        verdict = judge(Run(source, script),
                        (AstEngine(), VmEngine(0), VmEngine(level, counting=profile)), BUDGET)
        if verdict.problems:
            raise SystemExit(f"{path.name}: the levels disagree: {verdict.problems}")
        executed_by_opcode.update(verdict.observations[f"vm-O{level}"].opcodes or {})
        for instruction in verify(_compile(source, level)).instructions:
            code_bytes[instruction.info.name] += instruction.info.length
        executed: list[float] = [verdict.observations[f"vm-O{n}"].executed or 0
                                 for n in (0, level)]
        sizes: list[float] = [len(ilc.decode(_compile(source, n)).code) for n in (0, level)]
        times = [_compile_ms(source, n, repeat) for n in (0, level)]
        row = f"{path.stem:<16}"
        for key, (before, now) in zip(ratios, (executed, sizes, times), strict=True):
            ratios[key].append(now / before)
            figures = (f"{before:.2f} -> {now:.2f}" if key == "compile"
                       else f"{before:.0f} -> {now:.0f}")
            row += f"{figures:>22}{now / before:>8.2f}"
        print(row)
    means = {key: geometric_mean(values) for key, values in ratios.items()}
    fewer_instructions, fewer_bytes = GOALS.get(level, (0.0, 0.0))
    print(f"geometric mean over {len(programs)} programs of {name}: "
          f"instructions x{means['instructions']:.3f} "
          f"({1 - means['instructions']:.0%} fewer, goal >= {fewer_instructions:.0%}), "
          f"code bytes x{means['bytes']:.3f} "
          f"({1 - means['bytes']:.0%} fewer, goal >= {fewer_bytes:.0%}), "
          f"compile time x{means['compile']:.2f} (goal <= 2)\n")
    if profile:
        print_profile(name, level, code_bytes, executed_by_opcode)


def print_profile(name: str, level: int, code_bytes: Counter[str],
                  executed: Counter[str]) -> None:
    total_bytes, total_executed = code_bytes.total(), executed.total()
    print(f"{name}: where -O{level} goes, by opcode: code bytes of {total_bytes}, "
          f"instructions executed of {total_executed}")
    for opcode in sorted(code_bytes.keys() | executed.keys(),
                         key=lambda opcode: (-code_bytes[opcode], -executed[opcode], opcode)):
        print(f"  {opcode:<8}{code_bytes[opcode]:>6}{code_bytes[opcode] / total_bytes:>7.1%}"
              f"{executed[opcode]:>8}{executed[opcode] / total_executed:>7.1%}")
    print()


def _compile_ms(source: str, level: int, repeat: int) -> float:
    return best_time(lambda: _compile(source, level), repeat) * 1000


def _compile(source: str, level: int) -> bytes:
    output = compile_text(source, "bench.rob", level=level).output
    assert output is not None
    return output


if __name__ == "__main__":
    main()
