"""Campaigns (`rl1c sim --runs`, compiler/campaign.py), in one run:

- runs per second of Listing 1 on the sample world with noise on (`noise = true`:
  spec/simulator.md, "Noise"), in one process and on every core (the pool's start-up
  included: a campaign pays it once), and on local Dask clusters (compiler/executors.py)
  of 1 worker and of 2, the fastest of a few rounds;
- the memory of a long campaign: the resident size of a campaign in this process,
  sampled as the runs go, over `--memory-runs` runs (default 100,000) of a cheap program;
- last, a campaign of `--runs` runs (default 1,000) of Listing 1 through the command
  line, its summary as printed.

    .venv/bin/python bench/campaign.py [--runs N] [--rate-runs N] [--rounds N]
        [--memory-runs N]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rl1.compiler.campaign import Campaign, Tally, Task, campaign_seeds, task_for
from rl1.compiler.cli.sim_campaign import WINDOW_PER_JOB
from rl1.compiler.executors import workers
from rl1.vm.defaults import DEFAULT_BUDGET

ROOT = Path(__file__).parents[1]
PROGRAM = ROOT / "examples" / "sample.rob"
WORLD = ROOT / "examples" / "sample.world.toml"
RL1C = str(Path(sys.executable).with_name("rl1c"))
CHEAP_PROGRAM = "A=(ULT A)\n(END)\n"  # one noisy reading: a run of about a millisecond
SAMPLES = 10  # of the memory, over the long campaign


def noisy_world() -> bytes:
    """The sample world with the default noise: `noise = true` before its first table."""
    return b"noise = true\n" + WORLD.read_bytes()


def cpu_seconds() -> float:
    """CPU time of this process and of its workers that have ended."""
    own, workers = (resource.getrusage(who) for who in
                    (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return own.ru_utime + own.ru_stime + workers.ru_utime + workers.ru_stime


def measure(task: Task, runs: int, jobs: int, scheduler: str | None = None) -> float:
    """Runs per second of wall-clock time, on `jobs` local processes or on the cluster of
    `scheduler`, as `rl1c sim --runs` makes them."""
    started = time.perf_counter()
    with workers(jobs, scheduler) as held:
        done = sum(1 for _ in Campaign(task, campaign_seeds(0, runs), held.executor,
                                       WINDOW_PER_JOB * max(held.slots, 1), held.lost))
    return done / (time.perf_counter() - started)


def fastest_rates(task: Task, runs: int, rounds: int, cores: int) -> dict[str, float]:
    """The runs per second of each way of making them, the fastest of `rounds` rounds
    that take each way in turn (so that the load of the machine, shared, falls on all
    alike): one process, every core, and local Dask clusters of 1 and of 2 workers (a
    process each, one thread), reached through a scheduler's address as `--scheduler`
    reaches it."""
    from distributed import LocalCluster

    def cluster(count: int) -> LocalCluster:
        return LocalCluster(  # type: ignore[no-untyped-call]
            n_workers=count, threads_per_worker=1, processes=True,
            dashboard_address=":0")  # the dashboard on any free port

    with cluster(1) as one, cluster(2) as two:
        ways: dict[str, tuple[int, str | None]] = {
            "1 process": (1, None), f"{cores} processes": (cores, None),
            "Dask, 1 worker": (1, one.scheduler_address),
            "Dask, 2 workers": (1, two.scheduler_address)}
        for jobs, scheduler in ways.values():  # the workers' imports and caches
            measure(task, 4, jobs, scheduler)
        best: dict[str, float] = {}
        for _ in range(rounds):
            for name, (jobs, scheduler) in ways.items():
                best[name] = max(best.get(name, 0.0), measure(task, runs, jobs, scheduler))
    return best


def resident_mb() -> float:
    """This process's resident memory now (not its peak)."""
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


def memory_samples(runs: int) -> list[tuple[int, float]]:
    """The resident memory after every tenth of a campaign of `runs` runs of a cheap
    program, each run kept as the command keeps it (counted, written as a JSON line)."""
    task = task_for(CHEAP_PROGRAM, noisy_world(), "sample.noisy.world.toml", "vm",
                    DEFAULT_BUDGET, "cheap.rob")
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
    parser.add_argument("--memory-runs", type=int, default=100_000)
    options = parser.parse_args()
    cores = os.cpu_count() or 1
    task = task_for(PROGRAM.read_text(), noisy_world(), "sample.noisy.world.toml", "vm",
                    DEFAULT_BUDGET, PROGRAM.name)
    load = os.getloadavg()[0]  # other work on the machine takes cores from the pool
    cpu = cpu_seconds()
    measure(task, options.rate_runs, 1)
    one_cpu = (cpu_seconds() - cpu) * 1000 / options.rate_runs
    rates = fastest_rates(task, options.rate_runs, options.rounds, cores)
    one, every = rates["1 process"], rates[f"{cores} processes"]
    one_worker, two_workers = rates["Dask, 1 worker"], rates["Dask, 2 workers"]
    print(f"Listing 1 on the sample world with noise on, {options.rate_runs} runs, the "
          f"fastest of {options.rounds} rounds ({cores} cores, load average {load:.1f} "
          "before):")
    print(f"  1 process:       {one:6.1f} runs/s ({one_cpu:.0f} ms of CPU a run)")
    print(f"  {cores} processes:     {every:6.1f} runs/s ({every / one:.2f}x one process; "
          "the pool's start-up included)")
    print(f"  Dask, 1 worker:  {one_worker:6.1f} runs/s ({one_worker / one:.2f}x one "
          "process)")
    print(f"  Dask, 2 workers: {two_workers:6.1f} runs/s ({two_workers / one_worker:.2f}x "
          f"1 worker)")

    cheap = "; ".join(CHEAP_PROGRAM.splitlines())
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
