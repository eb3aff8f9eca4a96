"""A fuzzing campaign against every rl1c command: the attacks of the test suite's
bounded run (tests/support/hostile.py, the C engine's build cache among them), hostile
project files (rl1.toml) under `rl1c check`, and hostile clients of `rl1-lsp --tcp` and
`--ws` (one server each per campaign), for as long as asked. Prints how
many inputs ran, how many found a problem, and the first few problems.

    .venv/bin/python bench/hostile_fuzz.py --minutes 10
"""

from __future__ import annotations

import argparse
import functools
import re
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from rl1.compiler.reporting.project import ProjectFileError, load_project_file

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from support.cli import rl1c  # noqa: E402  (tests/ is put on the path just above)
from support.hostile import (  # noqa: E402
    GROWTH_BOUND_MIB,
    HostileConnection,
    ServedLsp,
    _mutated,
    _problems,
    cache_attack,
    hostile_connections,
    hostile_ilc_files,
    hostile_libraries,
    hostile_sources,
    hostile_worlds,
    ilc_attack,
    source_attack,
    transport_attack,
    world_attack,
)

Input = TypeVar("Input")

SEED_PROJECT_FILES = [
    b'[check]\nselect = ["W"]\nignore = ["W0603"]\nwarnings-as-errors = true\n',
    b'# the team\'s choice\n[check]\nignore = ["W06", "W0205"]  # noisy\n',
    b"[check]\nwarnings-as-errors = false\n",
]
# Values that break naive readers: huge numbers and strings, codes that do not exist,
# the wrong types, deep nesting, control characters.
HOSTILE_PROJECT_VALUES = [
    "9" * 5000, "-" + "9" * 5000, "1e999", "nan", "inf", "0x" + "f" * 5000, '"W"',
    '["W9999"]', '["' + "W" * 100_000 + '"]', '["w06"]', '[""]', "[1, 2]", "{}", "[[]]",
    "[" * 600 + "]" * 600, '"\\u0000"', "1979-05-27T07:32:00Z", "true", '["W", "W"]',
]
WARNED_PROGRAM = b"' a program with warnings and no errors\n:10 A=1\n(MOV 1,1)\n"


@st.composite
def hostile_project_files(draw: st.DrawFn) -> bytes:
    """Arbitrary bytes, the seeds mutated byte by byte, the seeds with one value
    replaced by a hostile one, and the seeds behind a UTF-8 byte order mark."""
    kind = draw(st.sampled_from(["bytes", "mutated", "value", "bom"]))
    if kind == "bytes":
        return draw(st.binary(max_size=400))
    seed_file = draw(st.sampled_from(SEED_PROJECT_FILES))
    if kind == "mutated":
        return _mutated(seed_file, draw)
    if kind == "bom":
        return b"\xef\xbb\xbf" + seed_file
    assignments = list(re.finditer(rb"(?m)^([\w-]+\s*=\s*)(.*?)(\s*(#.*)?)$", seed_file))
    chosen = draw(st.sampled_from(assignments))
    value = draw(st.sampled_from(HOSTILE_PROJECT_VALUES)).encode()
    return seed_file[:chosen.start(2)] + value + seed_file[chosen.end(2):]


def project_attack(data: bytes, folder: Path) -> list[str]:
    """`rl1c check` on a program under the rl1.toml `data`: a file the reader refuses
    must end with status 2 and a message naming it; one it accepts must check."""
    project, program = folder / "rl1.toml", folder / "warned.rob"
    project.write_bytes(data)
    program.write_bytes(WARNED_PROGRAM)
    result = rl1c("check", program)
    found = _problems("check", result, None)
    try:
        load_project_file(str(project))
    except ProjectFileError:
        if result.exit_code != 2 or str(project) not in result.stderr:
            found.append(f"check: a bad rl1.toml gave status {result.exit_code}: "
                         f"{result.output_bytes[-300:]!r}")
    except Exception as error:  # the reader must raise nothing else
        found.append(f"load_project_file: {type(error).__name__}: {str(error)[:200]}")
    else:
        if result.exit_code not in (0, 1):
            found.append(f"check: a readable rl1.toml gave status {result.exit_code}: "
                         f"{result.output_bytes[-300:]!r}")
    if data.startswith(b"\xef\xbb\xbf") and result.exit_code == 2:
        found.append(f"check: an rl1.toml behind a byte order mark is refused: "
                     f"{result.stderr[-200:]!r}")
    return found


def campaign(name: str, inputs: st.SearchStrategy[Input],
             attack: Callable[[Input, Path], list[str]], seconds: float,
             batch_size: int = 100) -> None:
    """Runs `attack` on inputs drawn from `inputs` until `seconds` have passed, in
    batches of `batch_size`, each with a seed of its own so that every batch draws
    afresh."""
    ran, failed, problems = 0, 0, []
    deadline = time.monotonic() + seconds
    batch = 0
    while time.monotonic() < deadline:
        @seed(batch)
        @settings(max_examples=batch_size, deadline=None, database=None,
                  suppress_health_check=list(HealthCheck))
        @given(data=inputs)
        def run(data: Input) -> None:
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
    kinds: dict[str, str] = {}  # the first problem of each kind
    for problem in problems:
        kinds.setdefault(problem[:60], problem)
    for problem in list(kinds.values())[:5]:
        print(f"  {problem}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    options = parser.parse_args()
    share = options.minutes * 60 / 7
    campaign("sources (check, fmt, compile, run)", hostile_sources(), source_attack, share)
    campaign(".ilc files (run, dis, asm)", hostile_ilc_files(), ilc_attack, share)
    campaign("world files (sim)", hostile_worlds(), world_attack, share)
    campaign("project files (rl1.toml, check)", hostile_project_files(), project_attack,
             share)
    campaign("the C engine's build cache (run --engine c)", hostile_libraries(),
             cache_attack, share, batch_size=5)  # a build, 2-3 s, each
    for transport, name in [("tcp", "rl1-lsp --tcp"), ("ws", "rl1-lsp --ws")]:
        server = ServedLsp(transport)
        try:
            campaign(f"{name} (hostile clients, then a well-behaved one)",
                     hostile_connections(transport), functools.partial(_on, server), share,
                     batch_size=10)  # up to seconds each
            print(f"  its peak memory: {server.peak_mib() - server.started_mib:.0f} MiB over "
                  f"what it held once started (bound {GROWTH_BOUND_MIB} MiB)")
        finally:
            server.stop()


def _on(server: ServedLsp, attack: HostileConnection, _folder: Path) -> list[str]:
    return transport_attack(server, attack)


if __name__ == "__main__":
    main()
