"""Front-end throughput: parse and check a generated RL/I program, against CPython's
`compile()` of a Python program of as many simple lines, in the same run.

Prints lines per second for both, their ratio (goal: at least 0.4), and how time grows
from 10,000 to 100,000 lines (goal: 10x the lines in at most 11x the time); for the
check on the tree (`analyze`, which the compiler runs) and for `rl1c check`'s, which
holds no tree (`diagnose`, checker/streaming.py).

    .venv/bin/python bench/parse_check.py [--lines 100000]
"""

from __future__ import annotations

import argparse
import random
from collections.abc import Callable
from functools import partial

from timing import best_time

from rl1.compiler.analysis import analyze, diagnose


def rl1_program(lines: int, seed: int = 1997) -> str:
    """A program of `lines` lines in the style of Listing 1: up to 95 sections (RL/I has
    only 100 labels), each headed by a label and a sensing call, with arithmetic and
    calls, and looping back on the sensing result."""
    rng = random.Random(seed)
    variables = "ABCDEFGHIJKLMNOPQRabcdefghijklmnopqr@"
    operators = "+-&|^<>"
    sections = max(1, min(95, lines // 20))
    body_lines = max(1, (lines - 4) // sections - 2)
    out: list[str] = ["'generated benchmark program", "(TRC 0); (KYC)"]
    for label in range(1, sections + 1):
        out.append(f":{label:02d} (IMG); A=x-{rng.randint(0, 300)}")
        for _ in range(body_lines):
            kind = rng.random()
            v, w = rng.choice(variables), rng.choice(variables)
            if kind < 0.45:
                terms = "".join(
                    rng.choice(operators) + (rng.choice(variables) if rng.random() < 0.5
                                             else str(rng.randint(0, 999)))
                    for _ in range(rng.randint(0, 4))
                )
                out.append(f"{v}={w}{terms}")
            elif kind < 0.6:
                out.append(f"{v}++; {w}--")
            elif kind < 0.8:
                out.append(f"(MOV {rng.randint(-12, 12)},{rng.randint(-12, 12)}); "
                           f"(STX {rng.randint(-1800, 1800)})")
            elif kind < 0.9:
                out.append(f"(CAM P {rng.randint(0, 784)}); B=(ULT {rng.choice('ABCD')})")
            else:
                out.append(f"{v}=$%04X ' comment" % rng.randint(0, 0xFFFF))
        out.append(f"?A<#{label:02d}")
    out += ["(MOV 0,0)"] * (lines - len(out) - 1) + ["(END)"]
    return "\n".join(out) + "\n"


def python_program(lines: int, seed: int = 1997) -> str:
    rng = random.Random(seed)
    names = [f"v{i}" for i in range(50)]
    return "".join(
        f"{rng.choice(names)} = {rng.choice(names)} + {rng.randint(0, 999)} - {rng.choice(names)}\n"
        for _ in range(lines)
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=100_000)
    parser.add_argument("--repeats", type=int, default=5)
    options = parser.parse_args()
    lines = options.lines

    rl1_text = rl1_program(lines)
    python_text = python_program(lines)
    analysis = analyze(rl1_text)  # warm-up, and a sanity check of the generator
    errors = [d for d in analysis.diagnostics if d.is_error]
    if len(rl1_text.splitlines()) != lines or errors:
        raise SystemExit(f"generator broken: {len(rl1_text.splitlines())} lines, "
                         f"{len(errors)} errors, e.g. {errors[:1]}")

    if diagnose(rl1_text) != analysis.diagnostics:
        raise SystemExit("rl1c check's path and the check on the tree disagree")

    python_seconds = best_time(lambda: compile(python_text, "<bench>", "exec"), options.repeats)
    python_rate = lines / python_seconds
    print(f"CPython compile()     : {lines} lines in {python_seconds:.3f} s = "
          f"{python_rate:,.0f} lines/s")
    small = lines // 10
    small_text = rl1_program(small)
    checks: list[tuple[str, Callable[[str], object]]] = [
        ("analyze (the tree)", analyze), ("diagnose (rl1c check)", diagnose)]
    for name, check in checks:
        rl1_seconds = best_time(partial(check, rl1_text), options.repeats)
        rl1_rate = lines / rl1_seconds
        print(f"RL/I {name:<21}: {lines} lines in {rl1_seconds:.3f} s = {rl1_rate:,.0f} "
              f"lines/s, ratio to CPython {rl1_rate / python_rate:.2f} (goal >= 0.40)")
        small_seconds = best_time(partial(check, small_text), options.repeats)
        print(f"  growth: {small} lines {small_seconds:.3f} s, {lines} lines "
              f"{rl1_seconds:.3f} s, time x{rl1_seconds / small_seconds:.1f} for lines x10 "
              "(goal <= 11)")


if __name__ == "__main__":
    main()
