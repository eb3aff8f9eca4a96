"""`rl1c fuzz` when an engine ends the process it runs in (the C VM's crash, an abort, the
memory exhausted): the program that does it is a finding of its own, named, shrunk and
written down, and the programs beside it are judged as ever, on any number of
processes."""

from __future__ import annotations

import errno
import faulthandler
import json
import os
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from support.cli import rl1c, without_progress
from support.planted import crashing_c_vm
from support.recording import Recording, recorded

from rl1.compiler import differential, executors, fuzz
from rl1.compiler.cli.fuzz import WORKER_LOST
from rl1.compiler.differential import (
    Engine,
    EngineUnavailable,
    Observation,
    VmEngine,
    judge,
    judge_apart,
    signature,
)
from rl1.compiler.executors import TaskProcessEnded, in_own_process, workers
from rl1.compiler.frontend.source import split_lines
from rl1.compiler.strategies import Run

pytestmark = pytest.mark.slow  # campaigns, on pools of processes

SEED = 3
COUNT = 12
KILLER = "ends-its-process"
SIGSEGV = f"{KILLER}: ended its process (signal SIGSEGV)"


@dataclass(frozen=True)
class _EndsItsProcess:
    """The -O0 VM, except on `program` (and `others`), where it ends its process as the C
    VM's crash would: by `signum`, or with the exit status `status` (os._exit) when it
    is None."""

    program: str
    signum: int | None = signal.SIGSEGV
    status: int = 0
    name: str = KILLER
    level: int = 0
    others: tuple[str, ...] = ()

    def run(self, case: Run, budget: int) -> Observation:
        if case.source == self.program or case.source in self.others:
            if self.signum is None:
                os._exit(self.status)
            faulthandler.disable()  # pytest's, which would print this process's stacks
            os.kill(os.getpid(), self.signum)
        return VmEngine(0).run(case, budget)


def _quiet(programs: int, elapsed: float, shrinking: int) -> None:
    pass


def _small_searches(monkeypatch: pytest.MonkeyPatch) -> None:
    """Searches of 4 programs; a few tries at shrinking (a finding of _EndsItsProcess,
    which ends its process on one program alone, cannot be shrunk)."""
    monkeypatch.setattr(fuzz, "BATCH", 4)
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 5)
    monkeypatch.setattr(fuzz, "REDUCE_TESTS", 5)


@pytest.fixture
def programs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The COUNT programs of the campaign of SEED, in searches of 4, in their order."""
    _small_searches(monkeypatch)
    path = tmp_path / "programs"
    outcome = fuzz.campaign([VmEngine(0), Recording(path)], 20_000, count=COUNT,
                            seconds=None, seed=SEED, progress=_quiet)
    assert outcome.programs == COUNT and outcome.finding is None
    return recorded(path)


def _on_processes(engines: list[Engine], jobs: int, keep_going: bool) -> fuzz.Outcome:
    renewals: list[None] = []
    with workers(jobs, lost=lambda: renewals.append(None), isolated=True) as held:
        outcome = fuzz.campaign(engines, 20_000, count=COUNT, seconds=None, seed=SEED,
                                progress=_quiet, executor=held.executor, jobs=held.slots,
                                keep_going=keep_going, lost=held.lost)
    assert renewals, "no worker process ended: the engine did not end its process"
    return outcome


@pytest.mark.parametrize("jobs", [1, 2])
def test_the_program_that_ends_its_worker_is_the_finding_and_the_others_are_judged(
        programs: list[str], tmp_path: Path, jobs: int) -> None:
    killer = programs[7]  # the last of the second search of three
    path = tmp_path / "judged"
    outcome = _on_processes([VmEngine(0), Recording(path), _EndsItsProcess(killer)],
                            jobs, keep_going=True)
    assert outcome.finding is not None and outcome.finding.case.source == killer
    assert outcome.counts == {SIGSEGV: 1} and outcome.programs == COUNT
    # Every program judged (some twice: those of a search lost with a worker; and the
    # programs shrinking tried).
    assert set(programs) <= set(recorded(path))
    # Its reproducer's runs are those of the engines before it.
    assert list(outcome.finding.verdict.observations) == ["vm-O0", "recording", KILLER]


def test_without_keep_going_the_campaign_stops_at_it_the_same_for_any_jobs(
        programs: list[str]) -> None:
    killer = programs[7]
    one, two = (_on_processes([VmEngine(0), _EndsItsProcess(killer)], jobs, False)
                for jobs in (1, 2))
    for outcome in (one, two):
        assert outcome.finding is not None and outcome.finding.case.source == killer
        assert outcome.finding.signature == SIGSEGV
    # The first two searches: the killer is the eighth program.
    assert one.programs == 8


def test_judged_apart_an_ordinary_run_is_judged_as_in_this_process() -> None:
    case = Run("A=1\nB=A+2\n", {})
    engines = [VmEngine(0), VmEngine(2)]
    assert judge_apart(case, engines, 100) == judge(case, engines, 100)


def test_judged_apart_an_exit_names_its_status_and_the_runs_before_it() -> None:
    case = Run("A=1\n", {})
    verdict = judge_apart(case, [VmEngine(0), _EndsItsProcess(case.source, None, 3),
                                 VmEngine(1)], 100)
    assert verdict.problems == [f"{KILLER}: ended its process (exit status 3)"]
    assert verdict.ended == "exit status 3"
    assert list(verdict.observations) == ["vm-O0", KILLER]
    assert signature(verdict) == f"{KILLER}: ended its process (exit status 3)"


def test_judged_apart_in_a_thread_its_process_is_spawned_not_forked(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # As a Dask worker judges, in a thread beside its event loop's: a fork there copies
    # the locks other threads hold, never released in the child (Python 3.12 warns).
    def fork() -> int:
        raise AssertionError("forked in a process of several threads")

    monkeypatch.setattr(os, "fork", fork)
    ordinary, ending = Run("A=1\nB=A+2\n", {}), Run("A=1\n", {})
    verdicts: list[differential.Verdict] = []

    def judging() -> None:
        verdicts.append(judge_apart(ordinary, [VmEngine(0), VmEngine(2)], 100))
        verdicts.append(judge_apart(ending, [VmEngine(0), _EndsItsProcess(ending.source),
                                             VmEngine(1)], 100))

    thread = threading.Thread(target=judging)
    thread.start()
    thread.join(timeout=120)
    assert not thread.is_alive(), "judge_apart in a thread did not end within 120 s"
    assert len(verdicts) == 2, "judge_apart in a thread failed: see its exception above"
    assert verdicts[0] == judge(ordinary, [VmEngine(0), VmEngine(2)], 100)
    assert verdicts[1].problems == [SIGSEGV] and verdicts[1].ended == "signal SIGSEGV"
    assert list(verdicts[1].observations) == ["vm-O0", KILLER]


def test_a_task_in_a_process_of_its_own_answers_raises_or_is_said_to_have_ended() -> None:
    # How a cluster's worker runs a search (rl1c fuzz --scheduler), so that an engine
    # that ends its process ends that one, not the worker.
    assert in_own_process((), pow, 2, 10) == 1024
    with pytest.raises(ZeroDivisionError):
        in_own_process((), divmod, 1, 0)
    with pytest.raises(TaskProcessEnded, match=r"^the task's process ended \(exit status 3\)$"):
        in_own_process((), os._exit, 3)
    assert in_own_process((), pow, 2, 11) == 2048  # in a new process
    with pytest.raises(TaskProcessEnded, match=r"\(signal SIGSEGV\)$"):
        in_own_process((), _EndsItsProcess("A=1\n").run, Run("A=1\n", {}), 100)
    first = in_own_process((), os.getpid)
    assert in_own_process((), os.getpid) == first != os.getpid()  # kept for the next


class _Interrupted(Exception):
    pass


def test_a_task_interrupted_in_its_own_process_leaves_no_answer_to_the_next() -> None:
    # Ctrl-C while the answer is awaited: the next task must get its own answer, not
    # the interrupted one's when it comes.
    in_own_process((), os.getpid)  # the process started, so the alarm finds the task

    def interrupt(signum: int, frame: object) -> None:
        raise _Interrupted

    previous = signal.signal(signal.SIGALRM, interrupt)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.2)
        with pytest.raises(_Interrupted):
            in_own_process((), time.sleep, 2)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    assert in_own_process((), pow, 2, 10) == 1024


def test_spawn_raises_a_call_it_cannot_pickle_before_it_starts_a_process(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # Started first, the process would end on a half-read input, never waited for.
    def popen(*args: object, **kwargs: object) -> None:
        raise AssertionError("a process started for a call that cannot be pickled")

    monkeypatch.setattr(subprocess, "Popen", popen)
    with pytest.raises(TypeError, match=r"cannot pickle '_thread\.lock' object"):
        executors.spawn(print, threading.Lock())


def test_a_process_of_its_own_that_cannot_be_started_leaks_no_pipe(
        monkeypatch: pytest.MonkeyPatch) -> None:
    def no_process(*args: object, **kwargs: object) -> None:
        raise BlockingIOError(errno.EAGAIN, os.strerror(errno.EAGAIN))

    monkeypatch.setattr(executors, "spawn", no_process)
    open_before = len(os.listdir("/proc/self/fd"))
    raised: list[BaseException] = []

    def starting() -> None:  # in a thread of its own: none of its own process yet
        try:
            in_own_process((), os.getpid)
        except BlockingIOError as error:
            raised.append(error)

    thread = threading.Thread(target=starting)
    thread.start()
    thread.join()
    assert isinstance(raised[0], BlockingIOError)
    assert len(os.listdir("/proc/self/fd")) == open_before


def test_a_process_of_its_own_ends_when_its_parent_does() -> None:
    # As a cluster's worker killed: its process must not wait for tasks for ever.
    parent = subprocess.run(
        [sys.executable, "-c", "import os; from rl1.compiler.executors import "
         "in_own_process; print(in_own_process((), os.getpid), flush=True); os._exit(0)"],
        capture_output=True, text=True, timeout=120, check=True)
    child = int(parent.stdout)
    deadline = time.monotonic() + 60
    while _alive(child):
        assert time.monotonic() < deadline, f"process {child} outlived its parent"
        time.sleep(0.05)


def _alive(pid: int) -> bool:
    """Whether the process `pid` runs (not ended, nor a zombie no one waits for)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


@dataclass(frozen=True)
class _Unpicklable:
    name: str = "unpicklable"
    level: int = 0
    held: threading.Lock = field(default_factory=threading.Lock)

    def run(self, case: Run, budget: int) -> Observation:
        raise AssertionError("never run: it cannot be sent to a process")


def test_judged_apart_in_a_thread_an_engine_that_cannot_be_pickled_leaks_no_pipe() -> None:
    # In a thread judge_apart spawns its process, which is given the engines pickled.
    open_before = len(os.listdir("/proc/self/fd"))
    raised: list[BaseException] = []

    def judging() -> None:
        try:
            judge_apart(Run("A=1\n", {}), [VmEngine(0), _Unpicklable()], 100)
        except TypeError as error:
            raised.append(error)

    thread = threading.Thread(target=judging)
    thread.start()
    thread.join()
    assert "cannot pickle '_thread.lock' object" in str(raised[0])
    assert len(os.listdir("/proc/self/fd")) == open_before


@dataclass(frozen=True)
class _Unavailable:
    name: str = "unavailable"
    level: int = 0

    def run(self, case: Run, budget: int) -> Observation:
        raise EngineUnavailable("this machine cannot run it")


def test_judged_apart_an_engine_this_machine_cannot_run_is_raised_here() -> None:
    with pytest.raises(EngineUnavailable, match="this machine cannot run it"):
        judge_apart(Run("A=1\n", {}), [VmEngine(0), _Unavailable()], 100)


@pytest.fixture
def named_killer(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    """`rl1c fuzz --engine ends-its-process` (in this process and those forked from it)
    ends its process on the eighth program of `rl1c fuzz --seed SEED`; that program."""
    return _named_killers(tmp_path, monkeypatch, [7])[0]


def _named_killers(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, indexes: list[int]
                   ) -> list[str]:
    """`rl1c fuzz --engine ends-its-process` (in this process and those forked from it)
    ends its process on the programs of `rl1c fuzz --seed SEED` at `indexes`; those
    programs, found by rl1c itself with an engine `recording`, so that the test follows
    the generator as it changes."""
    _small_searches(monkeypatch)
    path = tmp_path / "programs"
    killing: list[str] = []
    named = differential.engine_named

    def engine_named(name: str) -> Engine | None:
        if name == "recording":
            return Recording(path)
        return _EndsItsProcess(killing[0], others=tuple(killing[1:])) if name == KILLER \
            else named(name)

    monkeypatch.setattr(differential, "engine_named", engine_named)
    monkeypatch.setattr(fuzz, "engine_named", engine_named)
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", "recording", "--count",
                  str(COUNT), "--seed", str(SEED), "--jobs", "1", "--out", tmp_path)
    assert result.exit_code == 0, result.output
    killing.extend(recorded(path)[index] for index in indexes)
    return killing


def test_rl1c_fuzz_says_each_worker_an_engine_ends(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    # It said the first alone: the campaign warned of its first search lost, and gave
    # the pool a renewal that did nothing.
    _named_killers(tmp_path, monkeypatch, [2, 6])  # in the first search, and the second
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", KILLER, "--count", str(COUNT),
                  "--seed", str(SEED), "--jobs", "1", "--keep-going", "--out",
                  tmp_path / "out")
    assert result.exit_code == 1, result.output
    assert f"      2  {SIGSEGV}\n" in result.stdout
    assert without_progress(result.stderr) == [f"rl1c fuzz: warning: {WORKER_LOST}"] * 2


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_rl1c_fuzz_names_the_program_writes_its_reproducer_and_replays_it(
        named_killer: str, tmp_path: Path, jobs: str) -> None:
    out = tmp_path / "out"
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", KILLER, "--count", str(COUNT),
                  "--seed", str(SEED), "--jobs", jobs, "--out", out)
    assert result.exit_code == 1, result.output
    assert "Traceback" not in result.output
    assert "rl1c fuzz: warning: a worker process ended abruptly" in result.stderr
    # The killer is the eighth program; on 2 processes the third search may run a while.
    programs = int(result.stdout.split()[1])
    assert programs == 8 if jobs == "1" else 8 <= programs <= COUNT
    assert ("an engine ends the process it runs in\n\nthe smallest program found that "
            "does it:\n" in result.stdout and result.stdout.rstrip().endswith(
                f"{SIGSEGV}\n\nreproducer: {out / 'finding-1'} (program, sensor script, "
                f"each engine's run); replay: sh {out / 'finding-1' / 'replay.sh'}\n"
                "  = help: replay.sh names each engine's own command, to run the one that "
                "ends its process under a debugger"))
    # The language's lines: str.splitlines would also split at a vertical tab or a form
    # feed, which a generated program may hold as a blank.
    for number, line in enumerate(split_lines(named_killer), 1):
        assert f"{number:4} | {line}" in result.stdout
    folder = out / "finding-1"
    assert (folder / "program.rob").read_bytes().decode() == named_killer
    assert json.loads((folder / "engines.json").read_text()) == {
        "engines": ["vm-O0", KILLER], "budget": 20_000}
    assert (folder / "program.sensors.json").exists()
    assert sorted(path.name for path in folder.glob("run-*")) == [
        "run-1-vm-O0.json", f"run-2-{KILLER}.json"]
    assert json.loads((folder / f"run-2-{KILLER}.json").read_text())["status"] == {
        "code": "ended-process", "line": None, "message": "signal SIGSEGV"}
    assert "exec rl1c fuzz --replay" in (folder / "replay.sh").read_text()
    replayed = rl1c("fuzz", "--replay", folder)
    assert replayed.exit_code == 1, replayed.output
    assert replayed.stdout.startswith("replay: an engine still ends the process it runs "
                                      "in (budget 20000) on:\n")
    assert replayed.stdout.rstrip().endswith(SIGSEGV)


def test_rl1c_fuzz_keep_going_counts_it_in_its_group(named_killer: str, tmp_path: Path
                                                     ) -> None:
    out = tmp_path / "out"
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", KILLER, "--count", str(COUNT),
                  "--seed", str(SEED), "--jobs", "2", "--out", out, "--keep-going")
    assert result.exit_code == 1, result.output
    assert f"fuzz: {COUNT} programs in " in result.stdout
    assert (f"1 kind of disagreement (reference: vm-O0), by the programs that showed "
            f"each:\n      1  {SIGSEGV}\n         reproducer: {out / 'finding-1'}; "
            in result.stdout)
    assert (out / "finding-1" / "program.rob").read_bytes().decode() == named_killer



def test_json_statistics_count_it_among_the_endings_and_the_findings(
        named_killer: str, tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = rl1c("fuzz", "--engine", KILLER, "--engine", "vm-O0", "--count", str(COUNT),
                  "--seed", str(SEED), "--jobs", "2", "--out", out, "--keep-going",
                  "--format", "json")
    assert result.exit_code == 1, result.output
    document = json.loads(result.stdout)
    # How the first engine, the one that ends its process, ended each program.
    endings = document["endings"]
    assert document["programs"] == sum(endings.values()) == COUNT
    assert endings["ended-process"] == 1
    assert document["findings"] == [{"signature": SIGSEGV, "programs": 1,
                                     "reproducer": str(out / "finding-1")}]


@pytest.mark.needs_cc
def test_a_c_vm_that_crashes_is_a_finding_of_rl1c_fuzz(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    library = crashing_c_vm(tmp_path)
    # The c-ON engines load it, here and in the processes forked from here.
    monkeypatch.setattr(differential, "library", lambda: library)
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    (corpus / "crash.rob").write_text("B=1\nA=1234\nC=2\n", encoding="ascii")
    out = tmp_path / "out"
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", "c-O1", "--corpus", corpus,
                  "--count", "20", "--seed", "1", "--jobs", "1", "--keep-going", "--out", out)
    assert result.exit_code == 1, result.output
    assert "fuzz: 21 programs (the corpus of 1 first)" in result.stdout
    assert "      1  c-O1: ended its process (signal SIGSEGV)\n" in result.stdout
    # Shrunk, each program tried in a process of its own, to the line that crashes it.
    folder = next(path.parent for path in out.glob("finding-*/program.rob")
                  if path.read_text() == "A=1234\n")
    replayed = rl1c("fuzz", "--replay", folder)
    assert replayed.exit_code == 1, replayed.output
    assert replayed.stdout.rstrip().endswith("c-O1: ended its process (signal SIGSEGV)")


@dataclass(frozen=True)
class _EndsItsWorker:
    """An engine that ends the worker process of a campaign on every program, whether
    it runs there or in a process the worker forked to judge the program apart (as the
    kernel's out-of-memory killer may choose the worker): no program is to blame."""

    campaign: int  # the process id of the campaign, whose children are its workers
    name: str = "ends-its-worker"
    level: int = 0

    def run(self, case: Run, budget: int) -> Observation:
        os.kill(os.getpid() if os.getppid() == self.campaign else os.getppid(),
                signal.SIGKILL)
        return VmEngine(0).run(case, budget)


def test_a_worker_killed_each_time_whatever_program_it_judges_is_said_as_such(
        monkeypatch: pytest.MonkeyPatch) -> None:
    named = differential.engine_named

    def engine_named(name: str) -> Engine | None:
        return _EndsItsWorker(os.getpid()) if name == "ends-its-worker" else named(name)

    monkeypatch.setattr(differential, "engine_named", engine_named)
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", "ends-its-worker", "--count",
                  "4", "--seed", "3", "--jobs", "1")
    assert result.exit_code == 3, result.output
    assert result.stderr.endswith(
        "\nrl1c fuzz: error: a worker process ended abruptly 3 times running one search, though "
        "none of its programs ended the process that ran it (something killed the "
        "workers, or the memory ran out); the campaign runs again with --seed 3\n")
    assert "Traceback" not in result.output
