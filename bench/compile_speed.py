"""`rl1c compile`'s time against the compile on the syntax tree, in the same run.

`compile_text` checks a source past driver.TREE_CHARACTERS as `rl1c check` does,
holding no tree, and lowers each line as the check parses it, so that its memory stays
within spec/language.md's bound (bench/memory.py); a shorter one on its tree. The
reference parses the text once into a whole tree, checks and lowers that (`analyze`,
then `lower` of its tree). Each is timed on Listing 1 at each level (as `rl1c compile`
takes it, and streamed as if it were long) and on a 1 MiB source of `A=1` statements
(test_compile_memory.py's shape, whose code the default level's dead-store pass takes
down to one store: a 1 MiB program of unlike statements is past the 64 KiB of code an
.ilc holds) at the default level; the best of --repeat runs counts, the two compiles
taking turns. A ratio above 1 is the price of the bound.

    .venv/bin/python bench/compile_speed.py [--repeat 40] [--large-repeat 3]
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import replace
from functools import partial
from pathlib import Path

from timing import best_times

from rl1.compiler.analysis import analyze
from rl1.compiler.backend import driver
from rl1.compiler.backend.codegen import generate
from rl1.compiler.backend.driver import compile_text
from rl1.compiler.backend.lower import lower
from rl1.compiler.backend.optimize import LEVELS, optimize
from rl1.vm import ilc
from rl1.vm.defaults import DEFAULT_LEVEL

ROOT = Path(__file__).parent.parent
LARGE_BYTES = 2**20


def on_the_tree(text: str, level: int) -> bytes:
    """The reference: the .ilc bytes as the compile made them from a whole tree."""
    analysis = analyze(text)
    assert not analysis.has_errors, analysis.diagnostics
    image = generate(optimize(lower(analysis.program), level), "bench.rob")
    assert image.debug is not None
    debug = replace(image.debug, source_digest=ilc.source_digest(text))
    return ilc.encode(replace(image, debug=debug))


def compiled(text: str, level: int) -> bytes:
    output = compile_text(text, "bench.rob", level=level).output
    assert output is not None
    return output


def streamed(text: str, level: int) -> bytes:
    """compile_text as a source past TREE_CHARACTERS takes it, whatever its length."""
    shortest, driver.TREE_CHARACTERS = driver.TREE_CHARACTERS, 0
    try:
        return compiled(text, level)
    finally:
        driver.TREE_CHARACTERS = shortest


def large_program() -> str:
    """LARGE_BYTES of lines of 499 `A=1` statements."""
    line = ";".join(["A=1"] * 499) + "\n"
    return line * (LARGE_BYTES // len(line))


def row(name: str, compile_: Callable[[str, int], bytes], text: str, level: int,
        repeat: int) -> None:
    if compile_(text, level) != on_the_tree(text, level):
        raise SystemExit(f"{name} -O{level}: the two compiles disagree")
    reference, measured = best_times([partial(on_the_tree, text, level),
                                      partial(compile_, text, level)], repeat)
    scale, unit = (1000, "ms") if reference < 1 else (1, "s")
    print(f"  {name:<28} -O{level}  {measured * scale:9.2f} {unit:<2}  "
          f"tree {reference * scale:9.2f} {unit:<2}  ratio {measured / reference:5.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=40,
                        help="compiles of Listing 1 at each level; the best counts")
    parser.add_argument("--large-repeat", type=int, default=3,
                        help="compiles of the 1 MiB program; the best counts")
    options = parser.parse_args()
    print("compile_text (rl1c compile) against the compile on the tree (ratio = the "
          "first / the tree's)")
    sample = (ROOT / "examples" / "sample.rob").read_text(encoding="utf-8")
    for level in LEVELS:
        row("Listing 1", compiled, sample, level, options.repeat)
        row("Listing 1, streamed", streamed, sample, level, options.repeat)
    large = large_program()
    row(f"`A=1` lines, {len(large.encode()) / 2**20:.2f} MiB", compiled, large,
        DEFAULT_LEVEL, options.large_repeat)


if __name__ == "__main__":
    main()
