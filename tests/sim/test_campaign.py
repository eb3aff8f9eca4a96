"""Campaigns (`rl1c sim --runs N`, compiler/campaign.py): the Wilson interval against
published values, a success rate with a known closed form (an ultrasonic dropout of
chance 0.3 decides each run), runs equal to the `rl1c sim --seed` runs they name, the
same output for any --jobs, bounded memory, and a campaign stopped by a signal keeping
its runs and its summary."""

from __future__ import annotations

import dataclasses
import errno
import gc
import io
import json
import os
import shlex
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from concurrent.futures import BrokenExecutor, Executor, Future
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import IO, Any, ParamSpec, TypeVar

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support.campaigns import (
    DROPOUT,
    WALL_PROGRAM,
    WALL_WORLD,
    BrokenAfter,
    Instant,
    Lost,
    campaign_files,
)
from support.cli import Result, rl1c

from rl1.compiler import campaign, executors
from rl1.compiler.campaign import (
    MOST_RUNS_A_TASK,
    RESUBMISSIONS,
    SEEDS_KEPT,
    TASK_SECONDS,
    Campaign,
    Record,
    Tally,
    Task,
    Timing,
    campaign_seeds,
    run_batch,
    run_one,
    runs_a_task,
    task_for,
    wilson,
)
from rl1.compiler.cli import sim_campaign
from rl1.compiler.cli.sim_campaign import Progress
from rl1.compiler.executors import Renewed
from rl1.vm.defaults import DEFAULT_BUDGET

RL1C = str(Path(sys.executable).with_name("rl1c"))
P = ParamSpec("P")
T = TypeVar("T")


@pytest.fixture
def wall(tmp_path: Path) -> tuple[Path, Path]:
    return campaign_files(tmp_path, "wall", WALL_PROGRAM, WALL_WORLD)


def wall_task(world: str = WALL_WORLD) -> Task:
    return Task(WALL_PROGRAM, world.encode(), "wall.world.toml", budget=10_000)


def compiled_wall_task() -> Task:
    """The task `rl1c sim wall.rob --runs N` makes: the program compiled once."""
    return task_for(WALL_PROGRAM, WALL_WORLD.encode(), "wall.world.toml", "vm",
                    DEFAULT_BUDGET, "wall.rob")


# The Wilson interval ----------------------------------------------------------------------


@pytest.mark.parametrize(("successes", "runs", "low", "high"), [
    (0, 10, 0.0, 0.2775),  # Brown, Cai and DasGupta (2001); Newcombe (1998), table I
    (5, 10, 0.2366, 0.7634),
    (10, 10, 0.7225, 1.0),
    (81, 263, 0.2553, 0.3662),  # Newcombe (1998): 81/263
    (15, 148, 0.0624, 0.1605),  # Newcombe (1998): 15/148
])
def test_the_wilson_interval_has_its_published_values(successes: int, runs: int,
                                                      low: float, high: float) -> None:
    found = wilson(successes, runs)
    assert found == pytest.approx((low, high), abs=5e-5)


def test_the_wilson_interval_of_none_or_all_reaches_0_or_1_exactly() -> None:
    # Rounding once put the lower end of 0 of 234 at 1.7e-18, above the rate itself.
    assert wilson(0, 234)[0] == 0.0
    assert wilson(234, 234)[1] == 1.0


@given(runs=st.integers(1, 10**6), data=st.data())
def test_the_wilson_interval_holds_the_rate_and_mirrors_failures(runs: int,
                                                                 data: st.DataObject) -> None:
    successes = data.draw(st.integers(0, runs))
    low, high = wilson(successes, runs)
    assert 0.0 <= low <= successes / runs <= high <= 1.0
    mirrored = wilson(runs - successes, runs)
    assert (1 - mirrored[1], 1 - mirrored[0]) == pytest.approx((low, high), abs=1e-12)


# Seeds and the closed form ----------------------------------------------------------------


def test_the_seeds_follow_the_first_and_stay_in_sims_range() -> None:
    assert list(campaign_seeds(7, 3)) == [7, 8, 9]
    assert list(campaign_seeds(2**32 - 2, 2)) == [2**32 - 2, 2**32 - 1]
    with pytest.raises(ValueError, match=r"leave 0\.\.4294967295"):
        campaign_seeds(2**32 - 2, 3)


def test_a_rate_with_a_closed_form_lies_in_its_wilson_interval() -> None:
    tally = Tally()
    for record in Campaign(compiled_wall_task(), campaign_seeds(0, 1000), None, 1):
        tally.add(record)
    low, high = wilson(tally.successes, tally.runs)
    assert low <= 1 - DROPOUT <= high
    # Every failure is the dropout's: one group, the fault at line 4.
    assert [(key, group.count) for key, group in tally.failures()] == [
        (("argument-range", 4, ""), tally.runs - tally.successes)]


def test_without_noise_every_seed_makes_the_same_run(wall: tuple[Path, Path]) -> None:
    program, world = wall
    world.write_text(WALL_WORLD.split("[noise]")[0])
    result = rl1c("sim", program, "--world", world, "--runs", "5", "--jobs", "1")
    assert result.exit_code == 0, result.output
    assert "the world has no noise: every seed makes the same run" in result.stdout
    assert "success: 5 of 5, 100.0%" in result.stdout


# The runs are `rl1c sim --seed`'s, whatever --jobs -----------------------------------------


def test_a_campaigns_run_is_the_rl1c_sim_run_of_its_seed(wall: tuple[Path, Path]) -> None:
    program, world = wall
    records = {record.seed: record for record in
               Campaign(wall_task(), range(40), None, 1)}
    failed = next(seed for seed, record in records.items() if not record.success)
    for seed in (failed, next(seed for seed, r in records.items() if r.success)):
        single = rl1c("sim", program, "--world", world, "--seed", str(seed),
                      "--budget", "10000", "--format", "json")
        report = json.loads(single.stdout)
        record = records[seed]
        assert single.exit_code == record.exit_status
        assert report["status"]["code"] == record.outcome
        assert report["status"]["line"] == record.line
        assert report["instructions"] == record.instructions
        assert report["device_time"] == record.device_time
        assert report["track"][-1][1:] == list(record.pose)


def test_a_program_compiled_once_runs_as_its_source_compiled_each_run() -> None:
    source = wall_task()
    compiled = task_for(WALL_PROGRAM, source.world, source.world_name, "vm", source.budget,
                        source.source_name)
    assert isinstance(compiled.program, bytes)
    assert list(Campaign(compiled, range(30), None, 1)) == list(
        Campaign(source, range(30), None, 1))


def test_the_replay_command_of_a_failure_makes_that_failure(wall: tuple[Path, Path]) -> None:
    program, world = wall
    result = rl1c("sim", program, "--world", world, "--runs", "30", "--jobs", "1")
    replay = next(line.split("replay: ")[1] for line in result.stdout.splitlines()
                  if "replay: " in line)
    words = shlex.split(replay)
    assert words[:2] == ["rl1c", "sim"]
    again = rl1c(*words[1:])
    assert again.exit_code == 10  # the argument-range fault the group names
    assert "--> " + str(program) + ":4:1" in again.stdout


def test_the_output_is_the_same_for_one_job_and_two(wall: tuple[Path, Path],
                                                   tmp_path: Path) -> None:
    program, world = wall
    outputs = []
    for jobs in ("1", "2"):
        out = tmp_path / f"runs{jobs}.jsonl"
        result = rl1c("sim", program, "--world", world, "--runs", "60", "--jobs", jobs,
                      "--out", out)
        assert result.exit_code == 0, result.output
        outputs.append((result.stdout, out.read_bytes()))
    assert outputs[0] == outputs[1]
    lines = [json.loads(line) for line in outputs[0][1].splitlines()]
    assert [line["seed"] for line in lines] == list(range(60))
    assert all(list(line) == ["seed", "success", "outcome", "exit_status", "line", "message",
                              "safety", "goal", "device_time", "pose", "instructions"]
               for line in lines)  # as spec/simulator.md, "Campaigns", lists them
    assert {line["outcome"] for line in lines} == {"ok", "argument-range"}


# Memory and stopping ----------------------------------------------------------------------


def _failure(seed: int) -> Record:
    return Record(seed, "device-error", 13, 7, "stopped", "collision", None, (), 10,
                  (0.0, 0.0, 0.0), 5)


def test_a_tally_keeps_counts_and_a_few_seeds_never_the_runs() -> None:
    tally = Tally()
    for seed in range(10_000):
        tally.add(_failure(seed))
    [(key, group)] = tally.failures()
    assert key == ("device-error", 7, "collision")
    assert group.count == 10_000
    assert group.seeds == list(range(SEEDS_KEPT))


def test_a_workers_memory_stays_flat_over_runs_of_source() -> None:
    # The front end moves each run's garbage cycles to the oldest generation (its
    # collector_paused), which only a full collection frees: 130 objects a run were kept.
    task = dataclasses.replace(wall_task(), engine="ast")  # parsed at every run
    for seed in range(100):
        run_one(task, seed)
    before = len(gc.get_objects())
    for seed in range(100, 500):
        run_one(task, seed)
    assert len(gc.get_objects()) - before < 20_000  # at most COLLECT_EVERY runs' garbage


def test_a_campaign_holds_at_most_its_window_of_tasks_in_flight() -> None:
    instant = Instant()
    runs = iter(Campaign(wall_task(), range(400), instant, 4))
    for taken in range(1, 300):
        next(runs)
        whole = sum(max(seeds) < taken for seeds in instant.submitted)
        assert len(instant.submitted) - whole <= 4
    # The first window before any run is timed, a run a task; then as many as fill
    # TASK_SECONDS, here the most a task makes.
    assert instant.submitted[:4] == [(0,), (1,), (2,), (3,)]
    assert instant.submitted[4] == tuple(range(4, 4 + MOST_RUNS_A_TASK))


def test_a_campaign_given_the_timing_of_another_starts_with_tasks_of_its_size() -> None:
    timing = Timing()
    list(Campaign(compiled_wall_task(), range(10), Instant(), 2, timing=timing))
    assert timing.runs == 10
    instant = Instant()
    list(Campaign(compiled_wall_task(), range(10, 200), instant, 2, timing=timing))
    assert instant.submitted[:2] == [tuple(range(10, 10 + MOST_RUNS_A_TASK)),
                                     tuple(range(10 + MOST_RUNS_A_TASK,
                                                 10 + 2 * MOST_RUNS_A_TASK))]


@given(runs=st.integers(0, 10**6), seconds=st.floats(0, 10**5, allow_nan=False))
def test_a_task_makes_about_task_seconds_of_runs(runs: int, seconds: float) -> None:
    size = runs_a_task(runs, seconds)
    assert 1 <= size <= MOST_RUNS_A_TASK
    if runs == 0:  # nothing timed yet
        assert size == 1
        return
    each = seconds / runs
    assert size == 1 or size * each <= TASK_SECONDS  # not more than fill it
    assert size == MOST_RUNS_A_TASK or (size + 1) * each > TASK_SECONDS  # nor fewer


def test_a_batch_is_the_runs_of_its_seeds() -> None:
    task = compiled_wall_task()
    assert run_batch(task, (5, 3, 9)).records == tuple(run_one(task, seed)
                                                      for seed in (5, 3, 9))


@pytest.mark.parametrize("jobs", ["1", "2"])
@pytest.mark.parametrize(("signum", "status"), [(signal.SIGTERM, 143),
                                                 (signal.SIGINT, 130)])
def test_a_stopped_campaign_keeps_its_runs_and_prints_its_summary(
        wall: tuple[Path, Path], tmp_path: Path, signum: int, status: int,
        jobs: str) -> None:
    program, world = wall
    out = tmp_path / "runs.jsonl"
    with subprocess.Popen([RL1C, "sim", str(program), "--world", str(world), "--runs",
                           "1000000", "--jobs", jobs, "--out", str(out)],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as process:
        deadline = time.monotonic() + 60
        while (not out.exists() or out.read_text().count("\n") < 20) \
                and time.monotonic() < deadline:
            time.sleep(0.1)
        os.kill(process.pid, signum)
        stdout, stderr = process.communicate(timeout=60)
    assert process.returncode == status, stderr
    assert "Traceback" not in stderr
    assert "interrupted: the runs finished are kept" in stderr
    kept = [json.loads(line) for line in out.read_text().splitlines()]  # every line whole
    assert [line["seed"] for line in kept] == list(range(len(kept)))  # the first seeds
    assert len(kept) >= 20
    assert f"--runs {1_000_000 - len(kept)} --seed {len(kept)} --jobs {jobs}" in stderr
    assert f"{len(kept)} runs of" in stdout and "(stopped after" in stdout
    assert f"success: {sum(line['success'] for line in kept)} of {len(kept)}" in stdout


def test_out_never_replaces_an_input_and_an_unwritable_out_is_said(
        wall: tuple[Path, Path], tmp_path: Path) -> None:
    program, world = wall
    for target, role in ((program, "program"), (world, "world file")):
        result = rl1c("sim", program, "--world", world, "--runs", "2", "--out", target)
        assert result.exit_code == 2
        assert f"is the {role} itself" in result.stderr
    assert program.read_text() == WALL_PROGRAM and world.read_text() == WALL_WORLD
    result = rl1c("sim", program, "--world", world, "--runs", "2", "--out",
                  tmp_path / "no such folder" / "runs.jsonl")
    assert result.exit_code == 2
    assert "cannot write" in result.stderr and "Traceback" not in result.output


class _FillingDisk(io.FileIO):
    """A file on a disk with room for `room` bytes: a write past it writes what fits,
    then fails as a full disk does."""

    room = 0

    def write(self, data: Any) -> int:
        fits = max(0, self.room - self.tell())
        if len(data) <= fits:
            return super().write(data)
        super().write(bytes(data)[:fits])
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_a_full_disk_leaves_the_whole_lines_of_the_runs_before_and_names_the_file(
        wall: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """--out on a disk that filled was left with half a line at its end, and the message
    did not say which file."""
    program, world = wall
    out = tmp_path / "runs.jsonl"
    assert rl1c("sim", program, "--world", world, "--runs", "3", "--out", out).exit_code == 0
    first, second, _ = out.read_text().splitlines(keepends=True)
    _FillingDisk.room = len(first) + len(second) // 2

    def on_a_filling_disk(path: str, mode: str, encoding: str) -> IO[str]:
        return io.TextIOWrapper(io.BufferedWriter(_FillingDisk(path, mode)),
                                encoding=encoding)

    monkeypatch.setattr(sim_campaign, "open", on_a_filling_disk, raising=False)
    result = rl1c("sim", program, "--world", world, "--runs", "3", "--out", out)
    assert result.exit_code == 2, result.output
    assert f"cannot write the campaign file `{out}`" in result.stderr, result.stderr
    assert "free some space" in result.stderr and "Traceback" not in result.output
    assert out.read_text() == first  # the runs before, each line whole


def test_out_streams_to_a_fifo(wall: tuple[Path, Path], tmp_path: Path) -> None:
    """A pipe cannot say its position: the count of the whole lines' bytes asked it
    (tell) after the first line, and the campaign ended with status 2, `cannot write the
    output: underlying stream is not seekable; free some space`."""
    program, world = wall
    fifo = tmp_path / "runs.fifo"
    os.mkfifo(fifo)
    received: list[str] = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_text()))
    reader.start()
    result = rl1c("sim", program, "--world", world, "--runs", "3", "--jobs", "1",
                  "--out", fifo)
    # A writer of its own ends the reader's wait, should rl1c not have opened the FIFO;
    # there is no reader left to open it for (ENXIO) when the reader has read it all.
    try:
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
    except OSError as error:
        assert error.errno == errno.ENXIO, error
    reader.join()
    assert result.exit_code == 0, result.stderr
    assert [json.loads(line)["seed"] for line in received[0].splitlines()] == [0, 1, 2]


def test_out_to_standard_output_closed_by_head_ends_quietly(wall: tuple[Path, Path]) -> None:
    """`--out - | head -1`: the pipe closed early ends the campaign as it ends any command
    (status 1, nothing said), where 29c77a3 said it could not write the campaign file `-`."""
    program, world = wall
    with subprocess.Popen([RL1C, "sim", str(program), "--world", str(world), "--runs", "2000",
                           "--jobs", "1", "--out", "-"], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE) as process:
        assert process.stdout is not None and process.stderr is not None
        assert process.stdout.readline().startswith(b'{"seed":0,')
        process.stdout.close()  # as head does after its first line
        said = process.stderr.read().decode()
        process.wait(timeout=120)
    assert process.returncode == 1, said
    assert "error" not in said and "Traceback" not in said


def test_progress_is_a_line_every_few_seconds_when_standard_error_is_no_terminal() -> None:
    clock = iter([0.0, 1.0, 5.5, 7.0, 11.0])
    stream = io.StringIO()
    progress = Progress(100, stream, lambda: next(clock))  # started at 0.0
    tally = Tally()
    for seconds in (1.0, 5.5, 7.0, 11.0):
        tally.add(_failure(int(seconds)))
        progress.update(tally)
    assert stream.getvalue().splitlines() == [
        "2/100 runs, 0 succeeded (0.0%), 0.4 runs/s",  # at 5.5 s, then none at 7 s
        "4/100 runs, 0 succeeded (0.0%), 0.4 runs/s"]  # at 11 s


def test_a_worker_killed_in_a_campaign_loses_no_run(wall: tuple[Path, Path],
                                                    tmp_path: Path) -> None:
    program, world = wall
    out = tmp_path / "runs.jsonl"
    runs = 1500
    with subprocess.Popen([RL1C, "sim", str(program), "--world", str(world), "--runs",
                           str(runs), "--jobs", "2", "--out", str(out)],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as process:
        workers: list[int] = []
        deadline = time.monotonic() + 60
        while not workers and time.monotonic() < deadline:
            workers = _children(process.pid)
            time.sleep(0.05)
        os.kill(workers[0], signal.SIGKILL)
        stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 0, stderr
    assert "a worker process ended abruptly" in stderr and "Traceback" not in stderr
    kept = [json.loads(line) for line in out.read_text().splitlines()]
    assert [line["seed"] for line in kept] == list(range(runs))
    assert f"success: {sum(line['success'] for line in kept)} of {runs}" in stdout
    for seed in range(0, runs, 37):  # and each the run of its seed
        assert kept[seed] == run_one(compiled_wall_task(), seed).to_json()


KILLER = 5  # the seed whose run ends its worker process
BESIDE = 1.0  # s the run of the seed before it takes: it is under way on the other worker


RUNS = 20  # of the campaigns with a killer


@dataclasses.dataclass(frozen=True)
class Killed:
    """A campaign on two processes with a killer, and the same campaign in this process
    alone: what each printed, and its JSON lines."""

    two: Result
    lines: str
    alone: Result
    alone_lines: str


@pytest.fixture
def with_a_killer(wall: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                  ) -> Callable[[bool], Killed]:
    """Given whether every time, the campaign of RUNS runs on two processes where the run
    of KILLER ends the process that makes it (os._exit, as a crash in C would), and that
    of KILLER - 1 takes BESIDE seconds more (the pool's processes, forked from this one,
    have the double; this one makes the runs as they are)."""
    program, world = wall
    parent, made, real = os.getpid(), tmp_path / "killed once", campaign.run_one

    def campaign_on(jobs: str) -> tuple[Result, str]:
        out = tmp_path / f"{jobs}.jsonl"
        result = rl1c("sim", program, "--world", world, "--runs", str(RUNS), "--jobs", jobs,
                      "--out", out)
        return result, out.read_text()

    def killing(every_time: bool) -> Killed:
        def run(task: Task, seed: int) -> Record:
            if os.getpid() != parent and seed == KILLER and (every_time or not made.exists()):
                made.touch()
                os._exit(1)
            if os.getpid() != parent and seed == KILLER - 1:
                time.sleep(BESIDE)
            return real(task, seed)

        monkeypatch.setattr(campaign, "run_one", run)
        return Killed(*campaign_on("2"), *campaign_on("1"))

    return killing


def test_a_run_that_ends_its_worker_once_is_made_again_with_those_beside_it(
        with_a_killer: Callable[[bool], Killed]) -> None:
    killed = with_a_killer(False)
    assert killed.two.exit_code == 0, killed.two.output
    assert "a worker process ended abruptly" in killed.two.stderr
    # Every run, each once: the same lines and summary as the campaign alone.
    assert (killed.lines, killed.two.stdout) == (killed.alone_lines, killed.alone.stdout)


def test_a_run_that_ends_its_worker_each_time_is_named_and_those_before_it_kept(
        with_a_killer: Callable[[bool], Killed]) -> None:
    # The run before it, lost with it, was named: a new pool had started again from
    # there, and the killer, made beside it, broke it again at that seed.
    killed = with_a_killer(True)
    result = killed.two
    assert result.exit_code == 3, result.output
    assert (f"rl1c sim: error: the run of seed {KILLER} ended its worker each time it was "
            f"made: replay it alone (rl1c sim ") in result.stderr
    assert f"--runs {RUNS - KILLER - 1} --seed {KILLER + 1} --jobs 2" in result.stderr
    assert killed.lines.splitlines() == killed.alone_lines.splitlines()[:KILLER]
    assert f"{KILLER} runs of" in result.stdout and "Traceback" not in result.output


def _ends_its_process() -> None:
    os._exit(1)


def test_a_renewed_pool_makes_the_tasks_after_a_process_died() -> None:
    renewals: list[None] = []
    pool = Renewed(2, lambda: renewals.append(None))
    try:
        with pytest.raises(BrokenProcessPool):
            pool.submit(_ends_its_process).result(timeout=60)
        assert renewals == []  # made again only when needed
        assert [pool.submit(pow, 2, n).result(timeout=60) for n in range(3)] == [1, 2, 4]
        assert len(renewals) == 1
    finally:
        pool.shutdown()


class Forgetting(Executor):
    """A pool found broken after it took one task, which it never finishes: the task
    submitted while a ProcessPoolExecutor was being found broken, which its thread can
    miss (not in its list of tasks when it failed them)."""

    def __init__(self) -> None:
        self.taken = 0

    def submit(self, fn: Callable[P, T], /, *args: P.args, **kwargs: P.kwargs) -> Future[T]:
        if self.taken:
            raise BrokenProcessPool("a process ended abruptly")
        self.taken += 1
        return Future()


def test_a_task_the_broken_pool_missed_is_lost_when_the_pool_is_made_again(
        monkeypatch: pytest.MonkeyPatch) -> None:
    pools: list[Executor] = [Forgetting(), Instant()]
    monkeypatch.setattr(executors, "_pool", lambda jobs: pools.pop(0))
    pool = Renewed(2, lambda: None)
    missed = pool.submit(run_batch, compiled_wall_task(), (0,))
    made = pool.submit(run_batch, compiled_wall_task(), (1,))
    assert isinstance(missed.exception(timeout=0), BrokenProcessPool)  # not waited on
    assert made.result().records == (run_one(compiled_wall_task(), 1),)


def _children(pid: int) -> list[int]:
    """The processes whose parent is `pid`."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue  # ended meanwhile
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


# Usage ------------------------------------------------------------------------------------


@pytest.mark.parametrize(("extra", "message"), [
    (["--jobs", "2"], "--jobs is for a campaign of runs: give --runs N"),
    (["--runs", "3", "--trace", "all"], "--trace shows one run"),
    (["--runs", "3", "--format", "json"], "--format json shows one run"),
    (["--runs", "0"], "expected a whole number of at least 1"),
    (["--runs", "3", "--seed", "4294967294"], "the seeds 4294967294..4294967296 leave"),
    (["--runs", "3", "--jobs", "5000"], "--jobs 5000: at most 1024 processes"),
])
def test_campaign_options_out_of_place_are_usage_errors(
        wall: tuple[Path, Path], extra: list[str], message: str) -> None:
    program, world = wall
    result = rl1c("sim", program, "--world", world, *extra)
    assert result.exit_code == 2
    assert message in result.stderr


def test_a_run_finished_when_the_pool_breaks_is_kept() -> None:
    # The pool refused the next submission after the first record left the queue: that
    # record was neither yielded nor salvaged, and the campaign resumed after it.
    campaign = Campaign(compiled_wall_task(), range(5), BrokenAfter(2), window=2)
    made: list[Record] = []
    with pytest.raises(BrokenExecutor):
        made.extend(campaign)
    made.extend(campaign.salvage())
    assert [record.seed for record in made] == [0, 1]


@pytest.mark.parametrize("seed", [3, 6])  # a task of its own, and one of a batch
def test_a_run_lost_with_its_worker_is_made_again_in_its_place(seed: int) -> None:
    task = compiled_wall_task()
    losing = Instant(losing=seed, losses=RESUBMISSIONS)
    made = list(Campaign(task, range(20), losing, window=4, lost=(Lost,)))
    assert made == list(Campaign(task, range(20), None, 1))
    assert losing.made(seed) == 1 + RESUBMISSIONS
    if seed == 6:  # its batch's runs made again a task each, once
        assert losing.submitted[4:7] == [tuple(range(4, 20)), (4,), (5,)]
        assert losing.made(19) == 2


def test_a_run_lost_each_time_it_is_made_stops_the_campaign_after_the_runs_before_it() -> None:
    campaign = Campaign(compiled_wall_task(), range(20), Instant(losing=6, losses=99),
                        window=4, lost=(Lost,))
    made: list[Record] = []
    with pytest.raises(Lost):
        made.extend(campaign)
    assert [record.seed for record in made] == [0, 1, 2, 3, 4, 5]
    assert campaign.salvage() == []  # the runs after it are not the next seeds


def test_an_error_that_is_no_lost_worker_is_not_made_again() -> None:
    losing = Instant(losing=1, losses=1)
    with pytest.raises(Lost):
        list(Campaign(compiled_wall_task(), range(4), losing, window=2))
    assert losing.made(1) == 1


def test_a_stopped_campaign_keeps_the_rest_of_a_batch_it_was_yielding() -> None:
    campaign = Campaign(compiled_wall_task(), range(200), Instant(), window=2)
    runs = iter(campaign)
    made = [next(runs) for _ in range(10)]  # in the third task, of 64 runs from seed 2
    made.extend(campaign.salvage())
    assert [record.seed for record in made] == list(range(2 + 2 * MOST_RUNS_A_TASK))
