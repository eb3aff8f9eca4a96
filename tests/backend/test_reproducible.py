"""The same source gives the same bytes: every level, every output, whatever the hash
seed of the Python that compiles it (firmware builds, checksums and caches rely on it).

Each seed needs its own interpreter, so the sources are compiled in subprocesses
started with PYTHONHASHSEED set, and their digests compared."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rl1.compiler.backend.driver import EMITS, OPTIMIZATION_LEVELS
from rl1.compiler.strategies import checked_programs, programs

ROOT = Path(__file__).resolve().parents[2]
HASH_SEEDS = ("0", "1", "2", "3")

# Reads {name: source} as JSON and prints {name/level/emit: sha256 of the output}.
COMPILE_ALL = f"""
import hashlib, json, sys
from rl1.compiler.backend.driver import compile_text
sources = json.load(sys.stdin)
digests = {{}}
for name, text in sources.items():
    for level in {OPTIMIZATION_LEVELS!r}:
        for emit in {EMITS!r}:
            output = compile_text(text, name, emit=emit, level=level).output
            key = f"{{name}}/O{{level}}/{{emit}}"
            digests[key] = None if output is None else hashlib.sha256(output).hexdigest()
json.dump(digests, sys.stdout)
"""


def digests_under(seed: str, sources: dict[str, str]) -> dict[str, str | None]:
    environment = {**os.environ, "PYTHONHASHSEED": seed}
    done = subprocess.run([sys.executable, "-c", COMPILE_ALL], input=json.dumps(sources),
                          capture_output=True, text=True, env=environment, check=True)
    digests: dict[str, str | None] = json.loads(done.stdout)
    return digests


def assert_reproducible(sources: dict[str, str]) -> None:
    first, *others = (digests_under(seed, sources) for seed in HASH_SEEDS)
    assert len(first) == len(sources) * len(OPTIMIZATION_LEVELS) * len(EMITS)
    for seed, digests in zip(HASH_SEEDS[1:], others, strict=True):
        differing = sorted(key for key in first if digests[key] != first[key])
        assert differing == [], f"PYTHONHASHSEED={seed} changes {differing}"


def test_the_examples_and_the_bench_corpus_compile_to_the_same_bytes_under_any_hash_seed(
) -> None:
    files = [*sorted((ROOT / "examples").glob("*.rob")),
             *sorted((ROOT / "bench" / "corpus").glob("*.rob"))]
    sources = {path.relative_to(ROOT).as_posix(): path.read_text("utf-8") for path in files}
    assert len(sources) >= 6
    compiled = digests_under(HASH_SEEDS[0], sources)
    assert all(compiled.values()), "every example and corpus program compiles"
    assert_reproducible(sources)


def test_the_constant_listing_1_tripped_on_is_loaded_from_one_variable() -> None:
    # `D=0` after several variables hold 0: which one is loaded was picked in hash order.
    source = ":01 A=0\nB=0\nG=0\n:02 (TIM 1)\nD=0\nE=D+A\n#02\n"
    assert_reproducible({"holders.rob": source})


@settings(max_examples=3, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(st.one_of(checked_programs(), programs()), min_size=15, max_size=15))
def test_generated_programs_compile_to_the_same_bytes_under_any_hash_seed(
        generated: list[str]) -> None:
    assert_reproducible({f"generated{index}.rob": text for index, text in enumerate(generated)})
