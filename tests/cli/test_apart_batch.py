"""A batch engine (`exec-batch:COMMAND`) beside an engine that could end its process:
judged apart (`differential.judge_apart`, a fork a case: `rl1c reduce --engine` with a
C engine, `rl1c fuzz`'s searches run again after their worker died), the batch engine
is driven from the process that forks, so that its process is started once for every
case rather than once a case, and the verdicts are those of `judge`."""

from __future__ import annotations

import shlex
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import given, settings
from support import ROOT
from support.ending_rl1c import EndsOnLine
from support.planted import crashing_c_vm

from rl1.compiler import differential, fuzz
from rl1.compiler.differential import (
    BatchEngine,
    Engine,
    VmEngine,
    engine_named,
    judge,
    judge_apart,
)
from rl1.compiler.strategies import Run, runs

pytestmark = pytest.mark.slow  # a batch engine's process, a fork a case

RL1C = shlex.quote(str(Path(sys.executable).with_name("rl1c")))
ENDING_RL1C = str(ROOT / "tests" / "support" / "ending_rl1c.py")
CRASHING = "A=1234"  # the line on which EndsOnLine ends its process
KILLER = f"ends-on:{CRASHING}"


class Starts:
    """A batch engine, `rl1c run --batch`, that writes a byte to a file each time its
    process starts."""

    def __init__(self, folder: Path) -> None:
        self.path = folder / "starts"
        self.name = (f"exec-batch:printf . >>{shlex.quote(str(self.path))}; "
                     f"exec {RL1C} run --batch")
        engine = engine_named(self.name)
        assert isinstance(engine, BatchEngine)
        self.engine = engine

    @property
    def count(self) -> int:
        return len(self.path.read_bytes()) if self.path.exists() else 0


@pytest.fixture
def batch(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Starts]:
    starts = Starts(tmp_path_factory.mktemp("batch"))
    yield starts
    started = differential._BATCHES.pop(starts.engine.command, None)
    if started is not None:  # its process stopped, not left to the end of the session
        started.close()


def test_judged_apart_a_batch_engine_is_started_once_for_every_case(batch: Starts) -> None:
    engines: list[Engine] = [VmEngine(0), EndsOnLine(CRASHING), batch.engine]
    ordinary = [Run(f"A={number}\nB=A+{number}\n", {}) for number in range(6)]
    for case in ordinary:
        assert judge_apart(case, engines, 100) == judge(case, engines, 100)
    ended = judge_apart(Run(f"B=1\n{CRASHING}\n", {}), engines, 100)
    assert ended.problems == [f"{KILLER}: ended its process (signal SIGSEGV)"]
    assert list(ended.observations) == ["vm-O0", KILLER]
    assert judge_apart(ordinary[0], engines, 100) == judge(ordinary[0], engines, 100)
    assert batch.count == 1


@settings(max_examples=25)
@given(case=runs())
def test_judged_apart_with_a_batch_engine_every_run_is_judged_as_here(
        tmp_path_factory: pytest.TempPathFactory, case: Run) -> None:
    starts = Starts(tmp_path_factory.mktemp("batch"))
    try:
        engines: list[Engine] = [VmEngine(0), starts.engine, VmEngine(2)]
        assert judge_apart(case, engines, 20_000) == judge(case, engines, 20_000)
        assert judge_apart(case, engines, 20_000) == judge(case, engines, 20_000)
        assert starts.count == 1
    finally:
        differential._BATCHES.pop(starts.engine.command).close()


def test_a_fuzz_search_judged_apart_starts_its_batch_engine_once(batch: Starts) -> None:
    searched = fuzz.search(fuzz.Search(0, 7, 6, (VmEngine(0), batch.engine), 20_000,
                                       apart=True))
    assert searched.programs == 6 and not searched.findings
    assert batch.count == 1


def test_rl1c_reduce_with_a_batch_engine_beside_one_that_ends_its_process(
        batch: Starts, tmp_path: Path) -> None:
    program = tmp_path / "crash.rob"
    program.write_text(f"B=1\n{CRASHING}\nC=2\nD=B+C ' the sum\n", encoding="utf-8")
    ran = subprocess.run(
        [sys.executable, ENDING_RL1C, "reduce", str(program), "--engine", "vm-O0",
         "--engine", KILLER, "--engine", batch.name],
        capture_output=True, text=True, timeout=300)
    assert ran.returncode == 0, ran.stderr
    assert program.with_name("crash.reduced.rob").read_text(encoding="utf-8") == \
        f"{CRASHING}\n"
    assert f"difference kept: {KILLER}: ended its process (signal SIGSEGV)\n" in ran.stdout
    tests = int(ran.stdout.split(" tests", 1)[0].rsplit("\n", 1)[-1])
    assert tests > 5 and batch.count == 1


@pytest.mark.needs_cc
def test_rl1c_reduce_with_a_batch_engine_beside_a_crashing_c_vm(batch: Starts,
                                                                 tmp_path: Path) -> None:
    program = tmp_path / "crash.rob"
    program.write_text(f"B=1\n{CRASHING}\nC=2\nD=B+C ' the sum\n", encoding="utf-8")
    ran = subprocess.run(
        [sys.executable, ENDING_RL1C, "--c-library", str(crashing_c_vm(tmp_path)), "reduce",
         str(program), "--engine", "vm-O0", "--engine", "c-O1", "--engine", batch.name],
        capture_output=True, text=True, timeout=300)
    assert ran.returncode == 0, ran.stderr
    assert program.with_name("crash.reduced.rob").read_text(encoding="utf-8") == \
        f"{CRASHING}\n"
    assert "difference kept: c-O1: ended its process (signal SIGSEGV)\n" in ran.stdout
    assert batch.count == 1
