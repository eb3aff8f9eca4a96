"""A fuzzing campaign against every rl1c command: the attacks of the test suite's
bounded run (tests/support/hostile.py), for as long as asked. Prints how many inputs
ran, how many found a problem, and the first few problems.

    .venv/bin/python bench/hostile_fuzz.py --minutes 10
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from support.hostile import (  # noqa: E402  (tests/ is put on the path just above)
    hostile_ilc_files,
    hostile_sources,
    hostile_worlds,
    ilc_attack,
    source_attack,
    world_attack,
)

Attack = Callable[[bytes, Path], list[str]]


def campaign(name: str, inputs: st.SearchStrategy[bytes], attack: Attack,
             seconds: float) -> None:
    """Runs `attack` on inputs drawn from `inputs` until `seconds` have passed, in
    batches of 100, each with a seed of its own so that every batch draws afresh."""
    ran, failed, problems = 0, 0, []
    deadline = time.monotonic() + seconds
    batch = 0
    while time.monotonic() < deadline:
        @seed(batch)
        @settings(max_examples=100, deadline=None, database=None,
                  suppress_health_check=list(HealthCheck))
        @given(data=inputs)
        def run(data: bytes) -> None:
            nonlocal ran, failed
            ran += 1
            with tempfile.TemporaryDirectory() as folder:
                found = attack(data, Path(folder))
            if found:
                failed += 1
                problems.extend(found[:1])

        run()
        batch += 1
    print(f"{name}: {ran} inputs in {seconds:.0f} s, {failed} with a problem")
    for problem in problems[:5]:
        print(f"  {problem}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=1.0)
    options = parser.parse_args()
    third = options.minutes * 20
    campaign("sources (check, fmt, compile, run)", hostile_sources(), source_attack, third)
    campaign(".ilc files (run, dis, asm)", hostile_ilc_files(), ilc_attack, third)
    campaign("world files (sim)", hostile_worlds(), world_attack, third)


if __name__ == "__main__":
    main()
