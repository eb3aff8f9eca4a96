"""Campaigns on a Dask cluster (`rl1c sim --runs N --scheduler ADDRESS`,
compiler/executors.py): a real `dask scheduler` and two `dask worker` processes on
127.0.0.1 make the runs, and the JSON lines and the summary are the local campaign's
byte for byte, also when a worker is killed in the middle; without `distributed`, or
without a scheduler at the address, a message says what to do."""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import pytest
from support import ROOT, cluster_worker
from support.campaigns import WALL_PROGRAM, WALL_WORLD, campaign_files
from support.cli import rl1c, without_progress
from support.planted import crashing_c_vm

from rl1.compiler import differential
from rl1.compiler.cli.fuzz import WORKER_LOST
from rl1.compiler.cli.sim_campaign import WORKER_LOST as SIM_WORKER_LOST
from rl1.compiler.cli.sim_campaign import Setting, no_workers_left
from rl1.compiler.executors import Unavailable, _same_rl1, _threads, sources_digest

BIN = Path(sys.executable).parent
STARTED_WITHIN = 120  # s for the scheduler and the workers to start on a loaded machine


@dataclass
class Cluster:
    """A Dask scheduler on 127.0.0.1 and its single-threaded workers, each a process of
    its own writing a log under `logs`."""

    logs: Path
    processes: list[subprocess.Popen[bytes]] = field(default_factory=list)
    address: str = ""
    # Tries of a task on workers that die running it before the scheduler fails it with
    # KilledWorker (Dask's default is 3); None: Dask's default.
    allowed_failures: int | None = 0
    python_path: Path | None = None  # the PYTHONPATH of every process, unless told another
    environment: dict[str, str] = field(default_factory=dict)  # set in every process

    @property
    def workers(self) -> list[subprocess.Popen[bytes]]:
        return self.processes[1:]

    def start_scheduler(self) -> None:
        address_file = self.logs / "scheduler.json"  # its address, written: no port race
        scheduler = self._start("scheduler", "--host", "127.0.0.1", "--port", "0",
                                "--scheduler-file", str(address_file))
        deadline = time.monotonic() + STARTED_WITHIN
        while (address := scheduler_address(address_file)) is None:
            assert time.monotonic() < deadline, "the scheduler did not start"
            assert scheduler.poll() is None, self.log()
            time.sleep(0.1)
        self.address = address

    def start_worker(self, python_path: Path | None = None, *, nanny: bool = False,
                     preload: str | None = None) -> None:
        """A worker of one thread; with `nanny`, as `dask worker` starts one by default,
        under a nanny that starts it again when it dies; `preload` (a module) is loaded
        in it first."""
        self._start("worker", self.address, "--host", "127.0.0.1", "--nthreads", "1",
                    *(() if nanny else ("--no-nanny",)),
                    *(("--preload", preload) if preload else ()),
                    "--name", f"worker-{len(self.workers)}", python_path=python_path)

    def wait_for_workers(self, count: int) -> None:
        from distributed import Client

        with Client(self.address, timeout=STARTED_WITHIN,  # type: ignore[no-untyped-call]
                    set_as_default=False) as client:
            client.wait_for_workers(count, timeout=STARTED_WITHIN)

    def _start(self, role: str, *options: str, python_path: Path | None = None
               ) -> subprocess.Popen[bytes]:
        # A worker killed while it makes a run fails that run at once (allowed-failures
        # 0, where Dask would try it on up to three workers first), so that the
        # campaign's own resubmission is tested.
        python_path = python_path or self.python_path
        env = {**os.environ, **self.environment,
               **({"PYTHONPATH": str(python_path)} if python_path else {})}
        if self.allowed_failures is not None:
            env["DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES"] = str(self.allowed_failures)
        with open(self.logs / f"{role}-{len(self.processes)}.log", "wb") as log:
            process = subprocess.Popen([str(BIN / "dask"), role, *options, "--no-dashboard"],
                                       stdin=subprocess.DEVNULL, stdout=log,
                                       stderr=subprocess.STDOUT, env=env, cwd=self.logs)
        self.processes.append(process)
        return process

    def log(self) -> str:
        """What the scheduler and the workers printed, for a failed test's message."""
        return "\n".join(f"--- {path.name}\n{path.read_text(errors='replace')}"
                         for path in sorted(self.logs.glob("*.log")))


def scheduler_address(address_file: Path) -> str | None:
    """The address in a scheduler's --scheduler-file, or None until the file is written
    whole: the scheduler writes it in place, and a test once read it still empty."""
    try:
        return str(json.loads(address_file.read_text())["address"])
    except (FileNotFoundError, json.JSONDecodeError, KeyError):
        return None


@contextmanager
def _cluster(folder: Path, workers: int, allowed_failures: int | None = 0,
             python_path: Path | None = None, environment: dict[str, str] | None = None
             ) -> Iterator[Cluster]:
    """A scheduler and `workers` workers, killed at the end whatever happens."""
    logs = folder / "cluster"
    logs.mkdir()
    cluster = Cluster(logs, allowed_failures=allowed_failures, python_path=python_path,
                      environment=environment or {})
    try:
        cluster.start_scheduler()
        if workers:
            for _ in range(workers):
                cluster.start_worker()
            cluster.wait_for_workers(workers)
        yield cluster
    finally:
        for process in cluster.processes:
            process.kill()
            process.wait()


def test_a_scheduler_file_not_yet_written_whole_gives_no_address(tmp_path: Path) -> None:
    # Read as soon as it existed, it was once empty: a JSONDecodeError before any campaign.
    file = tmp_path / "scheduler.json"
    assert scheduler_address(file) is None
    file.write_text("")
    assert scheduler_address(file) is None
    file.write_text('{"type": "Scheduler", "address": "tcp://127.0.0.1:8786')
    assert scheduler_address(file) is None
    file.write_text('{"type": "Scheduler", "address": "tcp://127.0.0.1:8786"}')
    assert scheduler_address(file) == "tcp://127.0.0.1:8786"


@pytest.fixture
def cluster(tmp_path: Path) -> Iterator[Cluster]:
    """A scheduler and two workers of the test's own, which it may kill."""
    with _cluster(tmp_path, 2) as started:
        yield started


@pytest.fixture(scope="module")
def shared_cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cluster]:
    """A scheduler and two workers started once a module (on each pytest worker that runs
    its tests), for the tests that leave them as they found them: none killed, no
    setting changed, each campaign ended before the test does."""
    with _cluster(tmp_path_factory.mktemp("shared"), 2) as started:
        yield started


@pytest.fixture
def scheduler(tmp_path: Path) -> Iterator[Cluster]:
    """A scheduler without workers."""
    with _cluster(tmp_path, 0) as started:
        yield started


def _wall(folder: Path) -> tuple[Path, Path]:
    return campaign_files(folder, "wall", WALL_PROGRAM, WALL_WORLD)


def _local(program: Path, world: Path, runs: int, out: Path) -> str:
    """The summary of the campaign on this process alone; its lines in `out`."""
    result = rl1c("sim", program, "--world", world, "--runs", str(runs), "--jobs", "1",
                  "--budget", "10000", "--out", out)
    assert result.exit_code == 0, result.output
    return result.stdout


def test_a_campaign_on_a_cluster_is_the_local_campaign_byte_for_byte(
        shared_cluster: Cluster, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Named from here, where the workers (in the folder of their logs) find no such
    # files: each task carries the program and the world.
    monkeypatch.chdir(tmp_path)
    program, world = (Path(path.name) for path in _wall(tmp_path))
    local = _local(program, world, 200, tmp_path / "local.jsonl")
    remote = rl1c("sim", program, "--world", world, "--runs", "200", "--budget", "10000",
                  "--scheduler", shared_cluster.address, "--out", tmp_path / "cluster.jsonl")
    assert remote.exit_code == 0, remote.output + shared_cluster.log()
    assert remote.stdout == local
    assert (tmp_path / "cluster.jsonl").read_bytes() == (tmp_path / "local.jsonl").read_bytes()
    assert "success: " in local and "argument-range at line 4" in local  # runs of both kinds


def _under_way(program: Path, world: Path, runs: int, address: str, out: Path, made: int
               ) -> subprocess.Popen[str]:
    """`rl1c sim --runs` on the cluster at `address`, once it has written `made` runs to
    `out` (or ended, or taken too long)."""
    process = subprocess.Popen([str(BIN / "rl1c"), "sim", str(program), "--world", str(world),
                                "--runs", str(runs), "--budget", "10000", "--scheduler",
                                address, "--out", str(out)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + STARTED_WITHIN
    while (not out.exists() or out.read_text().count("\n") < made) \
            and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    return process


def test_a_worker_killed_in_a_campaign_on_a_cluster_loses_no_run(
        cluster: Cluster, tmp_path: Path) -> None:
    program, world = _wall(tmp_path)
    runs = 1000
    out = tmp_path / "cluster.jsonl"
    with _under_way(program, world, runs, cluster.address, out, made=100) as process:
        victim = cluster.workers[0]
        victim.send_signal(signal.SIGKILL)
        victim.wait()
        assert process.poll() is None, "the campaign ended before the worker was killed"
        stdout, stderr = process.communicate(timeout=STARTED_WITHIN)
    assert process.returncode == 0, stderr + cluster.log()
    assert "Traceback" not in stderr
    # Said once, though each of the tasks it had failed (KilledWorker, allowed failures 0).
    assert stderr.count("rl1c sim: warning: ") == 1  # beside the progress lines
    assert f"rl1c sim: warning: {SIM_WORKER_LOST}\n" in stderr
    local = _local(program, world, runs, tmp_path / "local.jsonl")
    assert stdout == local  # every run counted once: the summary is exact
    assert out.read_bytes() == (tmp_path / "local.jsonl").read_bytes()


def test_a_campaign_whose_workers_are_all_lost_says_so_and_waits_for_one(
        tmp_path: Path) -> None:
    # Its one worker killed, as `dask worker --no-nanny` is not started again: the runs
    # waited in silence for ever.
    program, world = _wall(tmp_path)
    runs = 1000
    out, said = tmp_path / "cluster.jsonl", tmp_path / "stderr.txt"
    with _cluster(tmp_path, 1) as cluster, open(said, "w") as stderr, subprocess.Popen(
            [str(BIN / "rl1c"), "sim", str(program), "--world", str(world), "--runs",
             str(runs), "--budget", "10000", "--scheduler", cluster.address, "--out",
             str(out)], stdout=subprocess.PIPE, stderr=stderr, text=True) as process:
        stdout = _lose_the_workers(
            cluster, process, said, lambda: out.exists() and out.read_text().count("\n") >= 100)
    assert process.returncode == 0, said.read_text() + cluster.log()
    assert f"rl1c sim: warning: {no_workers_left(cluster.address)}\n" in said.read_text()
    assert "Traceback" not in said.read_text()
    assert stdout == _local(program, world, runs, tmp_path / "local.jsonl")


@contextmanager
def _waiting_for_workers(scheduler: Cluster, program: Path, world: Path, out: Path,
                         said: Path) -> Iterator[subprocess.Popen[str]]:
    """`rl1c sim --runs 50` on `scheduler`, which has no workers, once it has said so
    (its standard error goes to `said`)."""
    with open(said, "w") as stderr, subprocess.Popen(
            [str(BIN / "rl1c"), "sim", str(program), "--world", str(world), "--runs", "50",
             "--budget", "10000", "--scheduler", scheduler.address, "--out", str(out)],
            stdout=subprocess.PIPE, stderr=stderr, text=True) as process:
        deadline = time.monotonic() + STARTED_WITHIN
        while "has no workers yet" not in said.read_text():
            assert process.poll() is None and time.monotonic() < deadline, said.read_text()
            time.sleep(0.1)
        yield process


def test_a_campaign_started_before_any_worker_says_so_and_waits_for_one(
        scheduler: Cluster, tmp_path: Path) -> None:
    program, world = _wall(tmp_path)
    out, said = tmp_path / "cluster.jsonl", tmp_path / "stderr.txt"
    with _waiting_for_workers(scheduler, program, world, out, said) as process:
        assert not out.exists() or not out.read_text()  # no run made without a worker
        scheduler.start_worker()
        stdout, _ = process.communicate(timeout=STARTED_WITHIN)
    assert process.returncode == 0, said.read_text() + scheduler.log()
    assert (f"rl1c sim: note: the scheduler at {scheduler.address} has no workers yet; the runs "
            f"wait for one (`dask worker {scheduler.address}`)") in said.read_text()
    assert stdout == _local(program, world, 50, tmp_path / "local.jsonl")
    assert out.read_bytes() == (tmp_path / "local.jsonl").read_bytes()


def test_without_distributed_the_extra_to_install_is_named(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    program, world = _wall(tmp_path)
    out = tmp_path / "runs.jsonl"
    out.write_text("kept\n")
    monkeypatch.setitem(sys.modules, "distributed", None)  # what `import` then refuses
    result = rl1c("sim", program, "--world", world, "--runs", "5", "--scheduler",
                  "tcp://127.0.0.1:8786", "--out", out)
    assert result.exit_code == 2
    assert "\nrl1c sim: error: --scheduler needs Dask's `distributed`, which is not installed" in (
        "\n" + result.stderr)
    assert "pip install 'rl1[cluster]'" in result.stderr
    assert "Traceback" not in result.output
    assert out.read_text() == "kept\n"  # not replaced by a campaign that never ran


def _refusing_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port  # closed: a connection is refused


def test_an_unreachable_scheduler_is_said_with_its_address_within_seconds(
        tmp_path: Path) -> None:
    program, world = _wall(tmp_path)
    out = tmp_path / "runs.jsonl"
    out.write_text("kept\n")
    address = f"tcp://127.0.0.1:{_refusing_port()}"
    started = time.monotonic()
    result = subprocess.run([str(BIN / "rl1c"), "sim", str(program), "--world", str(world),
                             "--runs", "5", "--scheduler", address, "--out", str(out)],
                            capture_output=True, text=True, timeout=60, check=False)
    assert result.returncode == 2
    assert f"\nrl1c sim: error: cannot reach a Dask scheduler at {address}" in "\n" + result.stderr
    assert f"`dask worker {address}`" in result.stderr
    assert "Traceback" not in result.stderr and "Exception ignored" not in result.stderr
    assert out.read_text() == "kept\n"
    assert time.monotonic() - started < 30  # 5 s of trying, and the command's start


@pytest.mark.parametrize(("address", "why"), [
    ("localhost", "missing port number in address 'localhost'"),
    ("http://127.0.0.1:8786", "unknown address scheme 'http'"),
])
def test_an_address_that_is_none_says_why(tmp_path: Path, address: str, why: str) -> None:
    program, world = _wall(tmp_path)
    result = rl1c("sim", program, "--world", world, "--runs", "5", "--scheduler", address)
    assert result.exit_code == 2
    assert f"error: cannot reach a Dask scheduler at {address} ({why}" in result.stderr


def _other_rl1(folder: Path) -> Path:
    """The PYTHONPATH of a worker left from another checkout: rl1 found first there, a
    copy of this one with one line more."""
    other = folder / "other" / "rl1"
    for package in ("compiler", "vm"):
        shutil.copytree(ROOT / package, other / package,
                        ignore=shutil.ignore_patterns("__pycache__", "c", "node_modules"))
    with open(other / "compiler" / "campaign.py", "a", encoding="utf-8") as changed:
        changed.write("# another rl1\n")
    return other.parent


def test_a_worker_running_another_rl1_is_refused_before_any_run(
        scheduler: Cluster, tmp_path: Path) -> None:
    scheduler.start_worker()
    scheduler.start_worker(python_path=_other_rl1(tmp_path))
    scheduler.wait_for_workers(2)
    program, world = _wall(tmp_path)
    out = tmp_path / "runs.jsonl"
    result = rl1c("sim", program, "--world", world, "--runs", "5", "--scheduler",
                  scheduler.address, "--out", out)
    assert result.exit_code == 2, result.output + scheduler.log()
    assert re.search(r"error: the Dask workers tcp://127\.0\.0\.1:\d+ of the scheduler at "
                     + re.escape(scheduler.address) + " run another rl1", result.stderr)
    assert "install the same rl1 there" in result.stderr and not out.exists()


def _no_rl1(folder: Path) -> Path:
    """The PYTHONPATH of a Dask process on a machine without rl1."""
    none = folder / "none" / "rl1"
    none.mkdir(parents=True)
    (none / "__init__.py").write_text('raise ImportError("no rl1 here")\n', encoding="utf-8")
    return none.parent


@pytest.mark.parametrize(("python_path", "said"), [
    (_no_rl1, "cannot read rl1's tasks (ImportError: no rl1 here)"),
    (_other_rl1, "runs another rl1 than this one (its sources differ)"),
])
def test_a_scheduler_without_this_rl1_is_refused_before_any_run(
        tmp_path: Path, python_path: Callable[[Path], Path], said: str) -> None:
    # It unpickles each task: without rl1, every run failed with a RuntimeError of
    # Dask's, an internal error of rl1c's.
    program, world = _wall(tmp_path)
    out = tmp_path / "runs.jsonl"
    with _cluster(tmp_path, 0, python_path=python_path(tmp_path)) as scheduler:
        scheduler.start_worker(tmp_path)  # this rl1 (the folder holds no other)
        scheduler.wait_for_workers(1)
        result = rl1c("sim", program, "--world", world, "--runs", "5", "--scheduler",
                      scheduler.address, "--out", out)
    assert result.exit_code == 2, result.output + scheduler.log()
    assert result.stderr.startswith(
        f"rl1c sim: error: the Dask scheduler at {scheduler.address} " + said), result.stderr
    assert "restart the scheduler" in result.stderr and not out.exists()
    assert "Traceback" not in result.output


def test_a_worker_running_another_rl1_that_joins_later_stops_the_campaign(
        scheduler: Cluster, tmp_path: Path) -> None:
    # Only the workers there at the start were checked: a later one made runs of its own
    # rl1, which the campaign kept as this one's.
    program, world = _wall(tmp_path)
    out, said = tmp_path / "runs.jsonl", tmp_path / "stderr.txt"
    with _waiting_for_workers(scheduler, program, world, out, said) as process:
        scheduler.start_worker(python_path=_other_rl1(tmp_path))
        stdout, _ = process.communicate(timeout=STARTED_WITHIN)
    assert process.returncode == 2, said.read_text() + scheduler.log()
    assert re.search(r"rl1c sim: error: the Dask worker tcp://127\.0\.0\.1:\d+, which joined the "
                     f"scheduler at {re.escape(scheduler.address)} after the start, runs "
                     r"another rl1 than this one \(its sources differ; install the same rl1 "
                     r"there, and restart that worker\): the runs finished are kept",
                     said.read_text()), said.read_text()
    assert "Traceback" not in said.read_text()
    assert out.read_text() == "" and "(stopped after 0 of 50)" in stdout


def test_a_server_that_is_no_scheduler_is_said(tmp_path: Path) -> None:
    program, world = _wall(tmp_path)
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()

        def answer() -> None:  # eight bytes of a frame's length, then nothing of it
            connection, _ = server.accept()
            with connection:
                connection.sendall(b"\xff" * 64)
                connection.recv(65536)

        threading.Thread(target=answer, daemon=True).start()
        address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
        result = rl1c("sim", program, "--world", world, "--runs", "5", "--scheduler", address)
    assert result.exit_code == 2
    assert f"error: cannot reach a Dask scheduler at {address} (" in result.stderr


def test_jobs_and_a_scheduler_together_are_a_usage_error(tmp_path: Path) -> None:
    program, world = _wall(tmp_path)
    result = rl1c("sim", program, "--world", world, "--runs", "5", "--jobs", "2",
                  "--scheduler", "tcp://127.0.0.1:8786")
    assert result.exit_code == 2
    assert "--jobs counts local processes, and --scheduler gives" in result.stderr


def test_the_command_of_the_runs_left_keeps_the_scheduler() -> None:
    setting = Setting("a.rob", "w.toml", 0, 100, 2, "vm", 10000, "tcp://cluster:8786")
    assert setting.rest(40, 60) == ("rl1c sim a.rob --world w.toml --runs 60 --seed 40 "
                                    "--scheduler tcp://cluster:8786 --budget 10000")


def test_a_scheduler_lost_while_its_workers_are_counted_is_said_so() -> None:
    # Lost just after it was reached: the ConnectionResetError went through as an
    # OSError, which the command line reported as "cannot write the output".
    class Reset:  # a client whose scheduler is gone
        def nthreads(self) -> dict[str, int]:
            raise ConnectionResetError(104, "Connection reset by peer")

    with pytest.raises(Unavailable, match=r"^the connection to the Dask scheduler at "
                       r"tcp://127\.0\.0\.1:8786 was lost \(\[Errno 104\] Connection reset"):
        _threads(Reset(), "tcp://127.0.0.1:8786")  # type: ignore[arg-type]


class _Checked:
    """A client of a scheduler running this rl1 whose workers answer `answers` (a digest,
    or the error a worker gave), as Dask's client.run gives them."""

    def __init__(self, answers: dict[str, str | Exception]) -> None:
        self.answers = answers

    def run_on_scheduler(self, function: Callable[[], str]) -> str:
        return function()

    def run(self, function: Callable[[], str], on_error: str = "raise"
            ) -> dict[str, str | Exception]:
        for answer in self.answers.values():
            if isinstance(answer, Exception) and on_error == "raise":
                raise answer
        return self.answers


def test_a_worker_gone_while_the_workers_are_checked_is_left_out() -> None:
    # Killed as the campaign began: its closed connection went through as the
    # scheduler's, "the connection to the Dask scheduler was lost (Address removed.)".
    from distributed.comm.core import CommClosedError

    client = _Checked({"tcp://127.0.0.1:1": CommClosedError("Address removed."),
                       "tcp://127.0.0.1:2": sources_digest()})
    _same_rl1(client, "tcp://127.0.0.1:8786")  # type: ignore[arg-type]
    client.answers["tcp://127.0.0.1:3"] = ModuleNotFoundError("No module named 'rl1'")
    with pytest.raises(Unavailable, match=r"^the workers of the Dask scheduler at "
                       r"tcp://127\.0\.0\.1:8786 cannot run rl1 \(ModuleNotFoundError: "):
        _same_rl1(client, "tcp://127.0.0.1:8786")  # type: ignore[arg-type]


# rl1c fuzz --scheduler -------------------------------------------------------------------


def _fuzz(*options: str) -> str:
    """`rl1c fuzz --count 150 --seed 5` with `options`: its summary without its times."""
    done = subprocess.run([str(BIN / "rl1c"), "fuzz", "--count", "150", "--seed", "5",
                           *options], capture_output=True, text=True, timeout=600,
                          check=False)
    assert done.returncode == 0, done.stderr
    return re.sub(r" in [\d.]+ s \([\d.]+ per second\)", "", done.stdout)


def test_fuzzing_on_a_cluster_runs_the_programs_of_local_processes(
        shared_cluster: Cluster, tmp_path: Path) -> None:
    connections = shared_cluster.log().count("Receive client connection")
    on_cluster = _fuzz("--scheduler", shared_cluster.address, "--out", str(tmp_path / "out"))
    assert shared_cluster.log().count("Receive client connection") == connections + 1
    assert on_cluster == _fuzz("--jobs", "1", "--out", str(tmp_path / "out"))
    assert "fuzz: 150 programs; engines ast, vm-O0, vm-O1, vm-O2; seed 5" in on_cluster


def test_fuzzing_with_an_unreachable_scheduler_says_so(tmp_path: Path) -> None:
    address = f"tcp://127.0.0.1:{_refusing_port()}"
    result = rl1c("fuzz", "--count", "10", "--scheduler", address, "--out",
                  tmp_path / "out")
    assert result.exit_code == 2
    assert result.stderr.startswith(
        f"rl1c fuzz: error: cannot reach a Dask scheduler at {address}")
    result = rl1c("fuzz", "--count", "10", "--jobs", "2", "--scheduler", address)
    assert result.exit_code == 2
    assert "--jobs counts local processes, and --scheduler gives" in result.stderr


def test_a_scheduler_lost_in_a_campaign_keeps_its_runs_and_says_how_to_go_on(
        cluster: Cluster, tmp_path: Path) -> None:
    program, world = _wall(tmp_path)
    runs = 100_000
    out = tmp_path / "cluster.jsonl"
    with _under_way(program, world, runs, cluster.address, out, made=50) as process:
        cluster.processes[0].kill()  # the scheduler
        stdout, stderr = process.communicate(timeout=STARTED_WITHIN)
    assert process.returncode == 2, stderr
    assert "Traceback" not in stderr
    kept = out.read_text().count("\n")
    assert f"{kept} runs of" in stdout and f"(stopped after {kept} of {runs})" in stdout
    assert (f"rl1c sim: error: the connection to the Dask scheduler at {cluster.address} was "
            f"lost: the runs finished are kept in {out}; to go on, run the seeds left: "
            f"rl1c sim {program} --world {world} --runs {runs - kept} --seed {kept} "
            f"--scheduler {cluster.address} --budget 10000") in stderr
    _local(program, world, kept, tmp_path / "local.jsonl")
    assert out.read_bytes() == (tmp_path / "local.jsonl").read_bytes()  # the first seeds


def test_fuzzing_on_a_cluster_whose_scheduler_is_lost_says_so(cluster: Cluster,
                                                              tmp_path: Path) -> None:
    connections = cluster.log().count("Receive client connection")  # the fixture's
    with subprocess.Popen([str(BIN / "rl1c"), "fuzz", "--count", "100000", "--seed", "1",
                           "--scheduler", cluster.address, "--out", str(tmp_path / "out")],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as process:
        deadline = time.monotonic() + STARTED_WITHIN
        while cluster.log().count("Receive client connection") == connections:
            assert process.poll() is None and time.monotonic() < deadline
            time.sleep(0.1)
        cluster.processes[0].kill()  # the scheduler
        _, stderr = process.communicate(timeout=STARTED_WITHIN)
    assert process.returncode == 2, stderr
    assert f"error: the connection to the Dask scheduler at {cluster.address} was lost" \
        in stderr
    assert "Traceback" not in stderr


def test_fuzzing_on_a_cluster_whose_workers_are_all_lost_says_so_and_waits_for_one(
        tmp_path: Path) -> None:
    said = tmp_path / "stderr.txt"
    with _cluster(tmp_path, 1) as cluster:
        connections = cluster.log().count("Receive client connection")  # the fixture's
        with open(said, "w") as stderr, subprocess.Popen(
                [str(BIN / "rl1c"), "fuzz", "--count", "20", "--seed", "1", "--scheduler",
                 cluster.address, "--out", str(tmp_path / "out")], stdout=subprocess.PIPE,
                stderr=stderr, text=True) as process:
            stdout = _lose_the_workers(
                cluster, process, said,
                lambda: cluster.log().count("Receive client connection") > connections)
    assert process.returncode == 0, said.read_text() + cluster.log()
    assert (f"rl1c fuzz: warning: the Dask scheduler at {cluster.address} has no workers left "
            "(killed, or out of memory: one is started again only under a nanny, `dask "
            "worker` without --no-nanny); the searches wait for one (`dask worker "
            f"{cluster.address}`)\n") in said.read_text()
    assert "fuzz: 20 programs in " in stdout and "all agreed" in stdout


def _lose_the_workers(cluster: Cluster, process: subprocess.Popen[str], said: Path,
                      started: Callable[[], bool]) -> str:
    """Kill the one worker of `cluster` once the campaign `process` has `started`, start
    another once it has said (in `said`) that none is left, and give its standard output
    at its end."""
    deadline = time.monotonic() + STARTED_WITHIN
    while not started():
        assert process.poll() is None and time.monotonic() < deadline, said.read_text()
        time.sleep(0.05)
    cluster.workers[0].send_signal(signal.SIGKILL)  # without a nanny: gone for good
    cluster.workers[0].wait()
    while "has no workers left" not in said.read_text():
        assert process.poll() is None and time.monotonic() < deadline, (
            said.read_text() + cluster.log())
        time.sleep(0.1)
    cluster.start_worker()
    stdout, _ = process.communicate(timeout=STARTED_WITHIN)
    return stdout


# Campaigns whose engines end their workers ------------------------------------------------

CRASH = "c-O1: ended its process (signal SIGSEGV)"
ENDED_WITHIN = 300  # s for a campaign of 21 programs whose workers die, on a loaded machine


@contextmanager
def _ending(folder: Path, allowed_failures: int | None,
            environment: dict[str, str] | None = None) -> Iterator[Cluster]:
    """Two workers, each under a nanny (which starts it again when it dies), as `dask
    worker` starts them by default, that preload support.cluster_worker: its engine
    ends-its-worker, and the planted crashing C VM when $PLANTED_C_VM names it (in
    `environment`). The scheduler finds it too: it unpickles the tasks, and their
    engines."""
    with _cluster(folder, 0, allowed_failures, ROOT / "tests", environment) as cluster:
        for _ in range(2):
            cluster.start_worker(nanny=True, preload="support.cluster_worker")
        cluster.wait_for_workers(2)
        yield cluster


@pytest.fixture(scope="module")
def planted_library(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """support.planted's crashing C VM, built once a module."""
    return crashing_c_vm(tmp_path_factory.mktemp("planted"))


@pytest.fixture(scope="module")
def crashing_cluster(tmp_path_factory: pytest.TempPathFactory, planted_library: Path
                     ) -> Iterator[Cluster]:
    """_ending's cluster whose workers' C VM is the planted one, started once a module:
    the campaigns that crash it end none of its workers (each search runs in a process
    of its own, which the crash ends), as the tests that share it check."""
    with _ending(tmp_path_factory.mktemp("crashing"), None,
                 {cluster_worker.PLANTED: str(planted_library)}) as cluster:
        yield cluster


@pytest.fixture
def crashing(crashing_cluster: Cluster, planted_library: Path,
             monkeypatch: pytest.MonkeyPatch) -> Cluster:
    """A cluster whose workers' C VM, and this process's, is the planted crashing one: a
    step after which A is 1234 ends the process with SIGSEGV. Dask's scheduler as it
    comes, which tries a task on 4 workers that die running it before it fails it with
    KilledWorker."""
    monkeypatch.setattr(differential, "library", lambda: planted_library)  # --replay here
    monkeypatch.setenv(cluster_worker.PLANTED, str(planted_library))  # and in rl1c fuzz
    return crashing_cluster


@contextmanager
def _crashing_campaign(cluster: Cluster, folder: Path, stderr: IO[str] | int,
                       *options: str) -> Iterator[subprocess.Popen[str]]:
    """`rl1c fuzz` of vm-O0 and c-O1 on `cluster`, a program that crashes the C VM first
    (its corpus), then 20 generated, its standard error to `stderr`; killed on leaving
    if it has not ended (a test that timed out)."""
    corpus = folder / "corpus"
    corpus.mkdir()
    (corpus / "crash.rob").write_text("B=1\nA=1234\nC=2\n", encoding="ascii")
    with subprocess.Popen([str(BIN / "rl1c"), "fuzz", "--engine", "vm-O0", "--engine",
                           "c-O1", "--corpus", str(corpus), "--count", "20", "--seed", "1",
                           "--scheduler", cluster.address, "--out", str(folder / "out"),
                           *options], stdout=subprocess.PIPE, stderr=stderr, text=True
                          ) as process:
        try:
            yield process
        finally:
            if process.poll() is None:
                process.kill()


def _fuzz_crashing(cluster: Cluster, folder: Path, *options: str
                   ) -> subprocess.CompletedProcess[str]:
    """_crashing_campaign to its end."""
    with _crashing_campaign(cluster, folder, subprocess.PIPE, *options) as process:
        stdout, stderr = process.communicate(timeout=ENDED_WITHIN)
    return subprocess.CompletedProcess(process.args, process.returncode, stdout, stderr)


def _the_crash(out: Path) -> Path:
    """The reproducer under `out` of the crash shrunk to its line, which still crashes."""
    folder = next(path.parent for path in out.glob("finding-*/program.rob")
                  if path.read_text() == "A=1234\n")
    replayed = rl1c("fuzz", "--replay", folder)
    assert replayed.exit_code == 1, replayed.output
    assert replayed.stdout.rstrip().endswith(CRASH)
    return folder


def _workers_lost(cluster: Cluster) -> int:
    """The workers that have left the scheduler of `cluster`, as its log says."""
    return (cluster.logs / "scheduler-0.log").read_text(errors="replace").count(
        "Remove worker addr: ")


@pytest.mark.needs_cc
def test_a_program_that_crashes_a_workers_c_vm_is_the_finding(
        crashing: Cluster, tmp_path: Path) -> None:
    lost = _workers_lost(crashing)  # by the campaigns of the tests before, which share it
    result = _fuzz_crashing(crashing, tmp_path)
    assert result.returncode == 1, result.stderr + crashing.log()
    assert "Traceback" not in result.stdout + result.stderr
    # The search ran in a process of its own on its worker, which lives on; where the
    # crash ended the worker, and Dask tried the search on 3 more, each ended alike,
    # before it failed it and the campaign judged its programs apart.
    assert _workers_lost(crashing) == lost, crashing.log()
    assert without_progress(result.stderr) == [f"rl1c fuzz: warning: {WORKER_LOST}"]
    assert ("an engine ends the process it runs in\n\nthe smallest program found that "
            f"does it:\n   1 | A=1234\n\n{CRASH}\n\nreproducer: ") in result.stdout
    folder = _the_crash(tmp_path / "out")
    assert f"reproducer: {folder} (program, sensor script, each engine's run)" \
        in result.stdout


@pytest.mark.needs_cc
def test_keep_going_on_a_cluster_goes_past_a_crash_and_counts_it(
        crashing: Cluster, tmp_path: Path) -> None:
    result = _fuzz_crashing(crashing, tmp_path, "--keep-going")
    assert result.returncode == 1, result.stderr + crashing.log()
    assert "Traceback" not in result.stdout + result.stderr
    assert "fuzz: 21 programs (the corpus of 1 first)" in result.stdout
    assert f"      1  {CRASH}\n" in result.stdout
    _the_crash(tmp_path / "out")


def test_a_worker_killed_each_time_on_a_cluster_is_said_as_such(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # The cluster's KilledWorker went through as an internal error with its traceback,
    # where a local pool's loss said what happened.
    named = differential.engine_named
    monkeypatch.setattr(differential, "engine_named", lambda name: (
        cluster_worker.EndsItsWorker() if name == "ends-its-worker" else named(name)))
    with _ending(tmp_path, 0) as cluster:  # each death a KilledWorker: 3, not 12
        result = rl1c("fuzz", "--engine", "vm-O0", "--engine", "ends-its-worker",
                      "--count", "4", "--seed", "3", "--scheduler", cluster.address)
    assert result.exit_code == 3, result.output + cluster.log()
    assert without_progress(result.stderr) == [f"rl1c fuzz: warning: {WORKER_LOST}"] * 3 + [
        "rl1c fuzz: error: a worker process ended abruptly 3 times running one search, though "
        "none of its programs ended the process that ran it (something killed the "
        "workers, or the memory ran out); the campaign runs again with --seed 3"]


@pytest.mark.needs_cc
def test_a_crash_on_workers_without_a_nanny_ends_none_of_them(
        tmp_path: Path, planted_library: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Dask tried the search on both workers, each ended for good, and failed it (allowed
    # failures 1): the campaign, whose search waited to run again apart, waited for a
    # worker for ever. Each search now runs in a process of its own on its worker.
    monkeypatch.setattr(differential, "library", lambda: planted_library)
    monkeypatch.setenv(cluster_worker.PLANTED, str(planted_library))
    with _cluster(tmp_path, 0, 1, ROOT / "tests") as cluster:
        for _ in range(2):
            cluster.start_worker(preload="support.cluster_worker")
        cluster.wait_for_workers(2)
        result = _fuzz_crashing(cluster, tmp_path)
        assert all(worker.poll() is None for worker in cluster.workers), cluster.log()
    assert result.returncode == 1, result.stderr + cluster.log()
    assert without_progress(result.stderr) == [f"rl1c fuzz: warning: {WORKER_LOST}"]
    assert f"that does it:\n   1 | A=1234\n\n{CRASH}\n\nreproducer: " in result.stdout
    assert _workers_lost(cluster) == 0, cluster.log()
    _the_crash(tmp_path / "out")
