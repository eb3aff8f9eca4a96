"""One digest of what the optimizer makes: the .ilc bytes of every program of
bench/corpus, bench/unseen and examples/, and of --count programs of the fuzzer's
generator (`strategies.runs()`, Hypothesis derandomized, without the literals of loaded
modules, as `rl1c fuzz` draws), each compiled at -O1 and -O2. A change meant only for
speed leaves the digest as it was: run it before and after, on the same Hypothesis, and
compare (so a campaign run on the code before still stands for the code after).

    .venv/bin/python bench/optimizer_output.py [--count 3000]
"""

from __future__ import annotations

import argparse
import hashlib
from pathlib import Path

from hypothesis import HealthCheck, Phase, given, settings

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.fuzz import only_hypothesis_constants
from rl1.compiler.strategies import Run, runs

ROOT = Path(__file__).parent.parent
FOLDERS = ("bench/corpus", "bench/unseen", "examples")
LEVELS = (1, 2)


def written_programs() -> list[tuple[str, str]]:
    return [(str(path.relative_to(ROOT)), path.read_text(encoding="utf-8"))
            for folder in FOLDERS for path in sorted((ROOT / folder).glob("*.rob"))]


def generated_programs(count: int) -> list[str]:
    """`count` sources of the fuzzer's generator, the same in every run."""
    sources: list[str] = []

    @settings(max_examples=count, database=None, derandomize=True, deadline=None,
              suppress_health_check=list(HealthCheck), phases=(Phase.generate,))
    @given(runs())
    def draw(run: Run) -> None:
        sources.append(run.source)

    with only_hypothesis_constants():
        draw()
    return sources


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=3000, help="generated programs")
    count = parser.parse_args().count
    programs = [*written_programs(),
                *((f"generated {n}", text) for n, text in enumerate(generated_programs(count)))]
    digest = hashlib.sha256()
    refused = 0
    for name, text in programs:
        for level in LEVELS:
            output = compile_text(text, "bench.rob", level=level).output
            refused += output is None
            digest.update(f"{name} -O{level} {len(output or b'')}\n".encode())
            digest.update(output or b"")
    print(f"{len(programs)} programs ({count} generated) at -O{', -O'.join(map(str, LEVELS))}"
          f", {refused} compiles refused: sha256 {digest.hexdigest()}")


if __name__ == "__main__":
    main()
