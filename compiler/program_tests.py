"""Running a test of a test file (compiler/test_file.py, spec/tests.md): what `rl1c test`
does for each `[[test]]`.

A test's program runs as `rl1c sim` runs it on a world (compiler/simulation.py) or as
`rl1c run` runs it on a sensor script (or on no script), through the run stage
(compiler/runner.py); a success rate is a campaign of seeded runs
(compiler/campaign.py) on the executor given, in seed order. `run_test` returns an
`Outcome`: passed, failed (what did not hold, and the run's story for the report), or an
error (a file that cannot be read or used, a program with errors): never an exception
for a problem of the user's files.
"""

from __future__ import annotations

import os
import stat
import time
from collections.abc import Sequence
from concurrent.futures import BrokenExecutor, Executor
from dataclasses import dataclass, replace
from typing import Literal

from msgspec import UnsetType

from rl1.compiler.analysis import analyze
from rl1.compiler.campaign import (
    COLLECT_EVERY,
    Campaign,
    Tally,
    Task,
    campaign_seeds,
    task_for,
)
from rl1.compiler.files import SourceError, read_bounded
from rl1.compiler.frontend.collector import FullCollections
from rl1.compiler.frontend.diagnostics import Diagnostic
from rl1.compiler.frontend.source import read_source
from rl1.compiler.runner import Finished, load_script, run
from rl1.compiler.simulation import Ending, Simulation
from rl1.compiler.test_file import CallPattern, Success, Test, parse_call
from rl1.vm.faults import RunResult
from rl1.vm.native import BuildError
from rl1.vm.scripted import LOST, Script, ScriptedDevice, ScriptError, TraceEntry
from rl1.vm.sim.device import SimDevice, SimEntry
from rl1.vm.sim.goal import Verdict
from rl1.vm.sim.world import World, WorldError, decode_world
from rl1.vm.verifier import VerifyError, verify

MAX_INPUT_BYTES = 16 * 2**20  # a program or a world: far more than any holds
WINDOW_PER_JOB = 8  # a campaign's runs in flight per worker

Status = Literal["passed", "failed", "error"]


@dataclass(frozen=True, slots=True)
class Case:
    """A test of the test file `file` (as given), its paths resolved from its folder."""

    file: str
    test: Test

    def path(self, relative: str) -> str:
        """A path of the test file, as from the folder `rl1c test` runs in."""
        return os.path.normpath(os.path.join(os.path.dirname(self.file), relative))

    @property
    def program(self) -> str:
        return self.path(self.test.program)

    @property
    def world(self) -> str | None:
        world = self.test.world
        return None if isinstance(world, UnsetType) else self.path(world)

    @property
    def sensors(self) -> str | None:
        sensors = self.test.sensors
        return None if isinstance(sensors, UnsetType) else self.path(sensors)


@dataclass(frozen=True, slots=True)
class Story:
    """One run, for the report to tell: the run stage's outcome, the device (its trace,
    and on the simulator its state), how a simulated run ended (None on a sensor
    script), and the program's source (None for an .ilc file) named `source_name`."""

    finished: Finished
    device: SimDevice | ScriptedDevice
    ending: Ending | None
    source_name: str
    source: str | None

    @property
    def result(self) -> RunResult:
        return self.finished.result

    @property
    def trace(self) -> Sequence[TraceEntry | SimEntry]:
        """Every call the device received (with, on a sensor script, the lost lines)."""
        return self.device.log if isinstance(self.device, ScriptedDevice) else self.device.trace

    @property
    def verdict(self) -> Verdict | None:
        return None if self.ending is None else self.ending.verdict


@dataclass(frozen=True, slots=True)
class Outcome:
    """How a test went: `problems` says what did not hold (failed) or why it could not
    run (error); `story` is its run's, `tally` its campaign's; `diagnostics` the
    program's errors, when they kept it from running."""

    status: Status
    problems: tuple[str, ...] = ()
    story: Story | None = None
    tally: Tally | None = None
    diagnostics: Sequence[Diagnostic] = ()
    source: str | None = None  # the program's, when it has `diagnostics`
    task: Task | None = None  # the campaign's
    seconds: float = 0.0


class Unusable(Exception):
    """A file of the test that cannot be read or used: the test is an error."""


# Each test compiles its program: without a full collection now and then
# (frontend/collector.py says why), 2,000 tests on a world took 500 MB.
_collections = FullCollections(COLLECT_EVERY)


def run_test(case: Case, executor: Executor | None = None, jobs: int = 1) -> Outcome:
    """Run the test `case` (a success rate's runs on `executor`, None: in this process,
    with `jobs` workers) and judge it."""
    _collections.count()
    started = time.perf_counter()
    try:
        for name in (case.program, case.world, case.sensors):
            _refuse_special(name)
        outcome = _judged(case, executor, jobs)
    except Unusable as error:
        outcome = Outcome("error", (str(error),))
    except SourceError as error:
        outcome = Outcome("error", (f"cannot read {error}" + (
            f"; {error.help}" if error.help else ""),))
    except BuildError as error:  # the C VM of --engine c
        outcome = Outcome("error", (str(error),))
    except BrokenExecutor:
        outcome = Outcome("error", ("a worker process of the success rate's runs ended "
                                    "abruptly (killed, or out of memory)",))
    return replace(outcome, seconds=time.perf_counter() - started)


def _refuse_special(name: str | None) -> None:
    """Unusable when the file `name` of a test is a FIFO, a device or a socket: a test
    file from elsewhere naming one would make `rl1c test` wait forever, or read without
    end. (A file that does not exist, or cannot be reached, is read's to report.)"""
    try:
        mode = os.stat(name).st_mode if name is not None else stat.S_IFREG
    except OSError:
        return
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        raise Unusable(f"{name} is not a regular file (a FIFO, a device or a socket); "
                       "name a file the test reads")


def _judged(case: Case, executor: Executor | None, jobs: int) -> Outcome:
    test = case.test
    program = _program(case)
    if isinstance(program, str) and (analysis := analyze(program)).has_errors:
        return Outcome("error", (f"{case.program} has errors: it cannot run",),
                       diagnostics=analysis.diagnostics, source=program)
    world = _world(case)
    if world is not None and world[1].goal is None and (
            not isinstance(test.expect.goal, UnsetType)):
        raise Unusable(f"the world file {case.world} has no [goal] to judge: add one "
                       "(spec/simulator.md, \"The goal\"), or leave out expect.goal")
    if isinstance(test.expect.success, Success):
        assert world is not None  # test_file.py refuses a success rate without a world
        return _success_rate(case, program, world[0], test.expect.success, executor, jobs)
    story = _one_run(case, program, world)
    problems = expectation_problems(test, story)
    return Outcome("failed", tuple(problems), story) if problems else Outcome("passed")


def _program(case: Case) -> str | bytes:
    """The program's source text, or the bytes of an .ilc file that the verifier accepts."""
    name = case.program
    if not name.lower().endswith(".ilc"):
        return read_source(name).text
    data = read_bounded(name, MAX_INPUT_BYTES, "an .ilc file")
    try:
        verify(data)
    except VerifyError as error:
        raise Unusable(f"{name} is not valid intermediate code: byte {error.offset}: "
                       f"{error.message}; compile the program again") from None
    return data


def _world(case: Case) -> tuple[bytes, World] | None:
    name = case.world
    if name is None:
        return None
    data = read_bounded(name, MAX_INPUT_BYTES, "a world file")
    try:
        return data, decode_world(data, name)
    except WorldError as error:
        raise Unusable(f"the world file is not valid: {error}") from None


def _script(case: Case) -> Script:
    name = case.sensors
    if name is None:
        return Script()
    try:
        return load_script(name)
    except ScriptError as error:
        raise Unusable(f"the sensor script is not valid: {error}") from None


def _one_run(case: Case, program: str | bytes, world: tuple[bytes, World] | None) -> Story:
    """The test's run, as `rl1c sim --seed` or `rl1c run --sensors` makes it."""
    source = program if isinstance(program, str) else None
    if world is None:
        device = ScriptedDevice(_script(case))
        return Story(_run(case, program, device), device, None, case.program, source)
    simulation = Simulation(world[1], case.test.seed)
    finished = _run(case, program, simulation.device)
    return Story(finished, simulation.device, simulation.end(finished.result), case.program,
                 source)


def _run(case: Case, program: str | bytes, device: SimDevice | ScriptedDevice) -> Finished:
    test = case.test
    try:
        finished = run(program, device, engine=test.engine, budget=test.budget,
                       source_name=os.path.basename(case.program))
    except ScriptError as error:  # losses after instruction counts, for the interpreter
        raise Unusable(str(error)) from None
    assert isinstance(finished, Finished)  # _judged ran only a program without errors
    return finished


def expectation_problems(test: Test, story: Story) -> list[str]:
    """What the test expects of its run that did not hold, each in a sentence."""
    expect = test.expect
    problems = []
    fault = story.result.fault
    ended = "normally" if fault is None else fault.kind.code
    if ended != expect.ends:
        how = "ended normally" if fault is None else f"ended with a fault, {fault.kind.code}"
        problems.append(f"expected the run to end {_ending(expect.ends)}, but it {how}")
    verdict = story.verdict
    if not isinstance(expect.goal, UnsetType) and verdict is not None and (
            verdict.met != (expect.goal == "met")):
        problems.append(f"expected the goal {expect.goal}, but {verdict.headline()}")
    values = story.result.named()
    wrong = [f"{name} = {value} (found {values[name]})"
             for name, value in expect.variables.items() if values[name] != value]
    if wrong:
        problems.append("expected " + ", ".join(wrong))
    patterns = {text: parse_call(text) for text in expect.calls}
    unseen = [text for text, pattern in patterns.items()
              if not any(_matches(pattern, entry) for entry in story.trace)]
    if unseen:
        problems.append("expected in the trace, but never called: "
                        + ", ".join(f"`{text}`" for text in unseen))
    return problems


def _ending(ends: str) -> str:
    return "normally" if ends == "normally" else f"with the fault {ends}"


def _matches(pattern: CallPattern | None, entry: TraceEntry | SimEntry) -> bool:
    if pattern is None or entry.call == LOST:
        return False
    form, args = pattern
    return entry.call == form and (args is None or tuple(entry.args) == args)


def _success_rate(case: Case, program: str | bytes, world: bytes, success: Success,
                  executor: Executor | None, jobs: int) -> Outcome:
    test = case.test
    task = task_for(program, world, case.world or "", test.engine, test.budget,
                    os.path.basename(case.program))
    tally = Tally()
    for record in Campaign(task, campaign_seeds(test.seed, success.runs), executor,
                           WINDOW_PER_JOB * jobs):
        tally.add(record)
    rate = tally.successes / tally.runs
    if rate >= success.at_least:
        return Outcome("passed", tally=tally, task=task)
    expected = (f"expected a success rate of at least {success.at_least:.1%} over "
                f"{success.runs} runs, but {tally.successes} of {tally.runs} succeeded "
                f"({rate:.1%})")
    return Outcome("failed", (expected,), tally=tally, task=task)
