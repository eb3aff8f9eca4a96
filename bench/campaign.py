"""Campaigns (`rl1c sim --runs`, compiler/campaign.py), in one run:

- runs per second of Listing 1 on the sample world with noise on (`noise = true`:
  spec/simulator.md, "Noise"), in one process and on every core (the pool's start-up
  included: a campaign pays it once), and on local Dask clusters (compiler/executors.py)
  of 1 worker and of 2, the fastest of a few rounds; and the CPU time of a run counted
  over every process (this one, the pool's or the cluster's, its scheduler included),
  which the load of a shared machine changes less than the rate;
- what Dask adds to a run: the CPU time of a run of a cheap program in one process and
  on a Dask worker (a campaign sends several runs a task: compiler/campaign.py);
- a sweep of many points of few runs each, on 1 Dask worker: the tasks sent and the runs
  per second with the runs' timing carried from point to point (as `rl1c sim --sweep`
  makes it) and begun again at each point (its tasks of one run until a run is timed);
- the memory of a long campaign: the resident size of a campaign in this process,
  sampled as the runs go, over `--memory-runs` runs (default 100,000) of a cheap program;
- last, a campaign of `--runs` runs (default 1,000) of Listing 1 through the command
  line, its summary as printed.

    .venv/bin/python bench/campaign.py [--runs N] [--rate-runs N] [--rounds N]
        [--memory-runs N] [--sweep-points N] [--sweep-runs N]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from concurrent.futures import Executor, Future
from dataclasses import dataclass, replace
from pathlib import Path
from typing import ParamSpec, TypeVar

import psutil  # type: ignore[import-untyped]  # with `distributed`, which this bench needs
from distributed import LocalCluster

from rl1.compiler.campaign import Campaign, Tally, Task, Timing, campaign_seeds, task_for
from rl1.compiler.cli.sim_campaign import WINDOW_PER_JOB
from rl1.compiler.executors import workers
from rl1.vm.defaults import DEFAULT_BUDGET

ROOT = Path(__file__).parents[1]
PROGRAM = ROOT / "examples" / "sample.rob"
WORLD = ROOT / "examples" / "sample.world.toml"
RL1C = str(Path(sys.executable).with_name("rl1c"))
CHEAP_PROGRAM = "A=(ULT A)\n(END)\n"  # one noisy reading: a run of about a millisecond
SAMPLES = 10  # of the memory, over the long campaign

P = ParamSpec("P")
T = TypeVar("T")


def noisy_world() -> bytes:
    """The sample world with the default noise: `noise = true` before its first table."""
    return b"noise = true\n" + WORLD.read_bytes()


def cpu_seconds() -> dict[int, float]:
    """The CPU time so far of this process (a local cluster's scheduler runs in it) and
    of each process under it (a pool's or a local cluster's workers), by process id."""
    seconds = {}
    me = psutil.Process()
    for process in (me, *me.children(recursive=True)):
        try:
            times = process.cpu_times()
        except psutil.NoSuchProcess:
            continue  # ended meanwhile
        seconds[process.pid] = times.user + times.system
    return seconds


@dataclass(frozen=True, slots=True)
class Rate:
    """How fast a campaign went: runs per second of wall-clock time, and milliseconds of
    CPU time a run over every process that took part."""

    runs_per_second: float
    cpu_ms: float


def measure(task: Task, runs: int, jobs: int, scheduler: str | None = None) -> Rate:
    """The rate of a campaign of `runs` runs on `jobs` local processes or on the cluster
    of `scheduler`, as `rl1c sim --runs` makes them."""
    started, cpu = time.perf_counter(), cpu_seconds()
    with workers(jobs, scheduler) as held:
        done = sum(1 for _ in Campaign(task, campaign_seeds(0, runs), held.executor,
                                       WINDOW_PER_JOB * max(held.slots, 1), held.lost))
        used = sum(now - cpu.get(pid, 0.0) for pid, now in cpu_seconds().items())
    return Rate(done / (time.perf_counter() - started), used * 1000 / done)


def _cluster(count: int) -> LocalCluster:
    """A local Dask cluster of `count` workers, a process each, one thread, reached
    through its scheduler's address as `--scheduler` reaches it."""
    return LocalCluster(  # type: ignore[no-untyped-call]
        n_workers=count, threads_per_worker=1, processes=True,
        dashboard_address=":0")  # the dashboard on any free port


def fastest_rates(task: Task, runs: int, rounds: int,
                  ways: dict[str, tuple[int, str | None]]) -> dict[str, Rate]:
    """The rate of each way of making runs (its local processes, or its cluster's
    scheduler), the fastest of `rounds` rounds that take each way in turn (so that the
    load of the machine, shared, falls on all alike), with the least CPU time a run of
    those rounds."""
    for jobs, scheduler in ways.values():  # the workers' imports and caches
        measure(task, 4, jobs, scheduler)
    best: dict[str, Rate] = {}
    for _ in range(rounds):
        for name, (jobs, scheduler) in ways.items():
            rate = measure(task, runs, jobs, scheduler)
            fastest = best.get(name, rate)
            best[name] = Rate(max(fastest.runs_per_second, rate.runs_per_second),
                              min(fastest.cpu_ms, rate.cpu_ms))
    return best


class Counting(Executor):
    """An executor's tasks, counted as they are submitted."""

    def __init__(self, executor: Executor) -> None:
        self.executor = executor
        self.tasks = 0

    def submit(self, fn: Callable[P, T], /, *args: P.args, **kwargs: P.kwargs) -> Future[T]:
        self.tasks += 1
        return self.executor.submit(fn, *args, **kwargs)


def sweep_rate(task: Task, points: int, runs: int, scheduler: str, carried: bool
               ) -> tuple[float, int]:
    """The runs per second of a sweep of `points` points (start.x moved by 0, 1, ... cm)
    of `runs` runs each on the cluster of `scheduler`, one campaign a point as `rl1c sim
    --sweep` makes them, their timing `carried` from point to point or not; and the
    tasks it sent."""
    started = time.perf_counter()
    timing = Timing()
    with workers(1, scheduler) as held:
        assert held.executor is not None  # a cluster's
        counting = Counting(held.executor)
        for point in range(points):
            moved = replace(task, offsets=(("start.x", float(point)),))
            for _ in Campaign(moved, campaign_seeds(0, runs), counting,
                              WINDOW_PER_JOB * max(held.slots, 1), held.lost,
                              timing if carried else Timing()):
                pass
    return points * runs / (time.perf_counter() - started), counting.tasks


def cheap_task() -> Task:
    return task_for(CHEAP_PROGRAM, noisy_world(), "sample.noisy.world.toml", "vm",
                    DEFAULT_BUDGET, "cheap.rob")


def resident_mb() -> float:
    """This process's resident memory now (not its peak)."""
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


def memory_samples(runs: int) -> list[tuple[int, float]]:
    """The resident memory after every tenth of a campaign of `runs` runs of a cheap
    program, each run kept as the command keeps it (counted, written as a JSON line)."""
    task = cheap_task()
    tally = Tally()
    samples = [(0, resident_mb())]
    with open(os.devnull, "w", encoding="utf-8") as lines:  # written, not held
        for record in Campaign(task, campaign_seeds(0, runs), None, 1):
            tally.add(record)
            lines.write(json.dumps(record.to_json(), separators=(",", ":")) + "\n")
            if tally.runs % (runs // SAMPLES) == 0:
                samples.append((tally.runs, resident_mb()))
    return samples


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=1000)
    parser.add_argument("--rate-runs", type=int, default=100)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--cheap-runs", type=int, default=2000)
    parser.add_argument("--memory-runs", type=int, default=100_000)
    parser.add_argument("--sweep-points", type=int, default=50)
    parser.add_argument("--sweep-runs", type=int, default=40)
    options = parser.parse_args()
    cores = os.cpu_count() or 1
    task = task_for(PROGRAM.read_text(), noisy_world(), "sample.noisy.world.toml", "vm",
                    DEFAULT_BUDGET, PROGRAM.name)
    load = os.getloadavg()[0]  # other work on the machine takes cores from the pool
    with _cluster(1) as one, _cluster(2) as two:
        rates = fastest_rates(task, options.rate_runs, options.rounds, {
            "1 process": (1, None), f"{cores} processes": (cores, None),
            "Dask, 1 worker": (1, one.scheduler_address),
            "Dask, 2 workers": (1, two.scheduler_address)})
        # What Dask adds to a run, seen on a cheap one.
        costs = fastest_rates(cheap_task(), options.cheap_runs, options.rounds, {
            "here": (1, None), "there": (1, one.scheduler_address)})
        sweeps = {carried: max(sweep_rate(cheap_task(), options.sweep_points,
                                          options.sweep_runs, one.scheduler_address,
                                          carried) for _ in range(options.rounds))
                  for carried in (False, True)}
    one, every = rates["1 process"], rates[f"{cores} processes"]
    one_worker, two_workers = rates["Dask, 1 worker"], rates["Dask, 2 workers"]
    print(f"Listing 1 on the sample world with noise on, {options.rate_runs} runs, the "
          f"fastest of {options.rounds} rounds ({cores} cores, load average {load:.1f} "
          "before), and the least CPU time a run over every process:")
    for name, rate, against in [
            ("1 process", one, ""),
            (f"{cores} processes", every, f"{every.runs_per_second / one.runs_per_second:.2f}x "
             "one process; the pool's start-up included"),
            ("Dask, 1 worker", one_worker,
             f"{one_worker.runs_per_second / one.runs_per_second:.2f}x one process"),
            ("Dask, 2 workers", two_workers,
             f"{two_workers.runs_per_second / one_worker.runs_per_second:.2f}x 1 worker")]:
        print(f"  {name + ':':<17}{rate.runs_per_second:6.1f} runs/s"
              + (f" ({against})" if against else "") + f", {rate.cpu_ms:.1f} ms of CPU a run")

    cheap = "; ".join(CHEAP_PROGRAM.splitlines())
    here, there = costs["here"], costs["there"]
    print(f"\nwhat Dask adds to a run: {options.cheap_runs:,} runs of `{cheap}`, the fastest "
          f"of {options.rounds} rounds, and the least CPU time a run over every process:")
    print(f"  in one process:     {here.cpu_ms:5.2f} ms ({here.runs_per_second:.0f} runs/s)")
    print(f"  on one Dask worker: {there.cpu_ms:5.2f} ms ({there.runs_per_second:.0f} runs/s; "
          f"{there.cpu_ms - here.cpu_ms:+.2f} ms a run)")

    print(f"\na sweep of {options.sweep_points} points of {options.sweep_runs} runs of "
          f"`{cheap}` on one Dask worker, the fastest of {options.rounds} rounds:")
    (fresh, fresh_tasks), (carried, carried_tasks) = sweeps[False], sweeps[True]
    print(f"  timing begun again at each point: {fresh_tasks:5} tasks, {fresh:6.0f} runs/s")
    print(f"  timing carried over (rl1c sim):   {carried_tasks:5} tasks, {carried:6.0f} "
          f"runs/s ({carried / fresh:.2f}x)")

    print(f"\nmemory of a campaign of {options.memory_runs:,} runs of `{cheap}` on the "
          "sample world with noise on (resident, this process):")
    started = time.perf_counter()
    samples = memory_samples(options.memory_runs)
    seconds = time.perf_counter() - started
    for runs, megabytes in samples:
        print(f"  after {runs:>7,} runs: {megabytes:6.1f} MB")
    first = samples[1][1]  # after the first tenth: the caches and the collector settled
    print(f"  growth from the first tenth to the end: {samples[-1][1] - first:+.1f} MB "
          f"({options.memory_runs / seconds:.0f} runs/s)")

    with tempfile.TemporaryDirectory() as folder:
        shutil.copy(PROGRAM, folder)
        Path(folder, "sample.noisy.world.toml").write_bytes(noisy_world())
        command = ["rl1c", "sim", PROGRAM.name, "--world", "sample.noisy.world.toml",
                   "--runs", str(options.runs)]
        print(f"\n$ {' '.join(command)}")
        started = time.perf_counter()
        done = subprocess.run([RL1C, *command[1:]], cwd=folder, capture_output=True,
                              text=True, check=False)
        seconds = time.perf_counter() - started
    print(done.stdout, end="")
    print(f"(exit status {done.returncode}, {seconds:.1f} s, "
          f"{options.runs / seconds:.1f} runs/s with the command's start-up)")


if __name__ == "__main__":
    main()
