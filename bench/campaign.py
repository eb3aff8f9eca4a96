"""Campaigns (`rl1c sim --runs`, compiler/campaign.py): runs per second of Listing 1 on
the sample world with noise on (`noise = true`: spec/simulator.md, "Noise"), in one
process and on every core (the pool's start-up included: a campaign pays it once), then
a campaign of `--runs` runs (default 1,000) through the command line, its summary as
printed.

    .venv/bin/python bench/campaign.py [--runs N] [--rate-runs N]
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from rl1.compiler.campaign import Campaign, Task, campaign_seeds, task_for
from rl1.vm.defaults import DEFAULT_BUDGET

ROOT = Path(__file__).parents[1]
PROGRAM = ROOT / "examples" / "sample.rob"
WORLD = ROOT / "examples" / "sample.world.toml"
RL1C = str(Path(sys.executable).with_name("rl1c"))


def noisy_world() -> bytes:
    """The sample world with the default noise: `noise = true` before its first table."""
    return b"noise = true\n" + WORLD.read_bytes()


def cpu_seconds() -> float:
    """CPU time of this process and of its workers that have ended."""
    own, workers = (resource.getrusage(who) for who in
                    (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return own.ru_utime + own.ru_stime + workers.ru_utime + workers.ru_stime


def measure(task: Task, runs: int, jobs: int) -> tuple[float, float]:
    """Runs per second of wall-clock time, and CPU ms a run (this process and the
    workers together: what the machine's load does not change)."""
    started, cpu = time.perf_counter(), cpu_seconds()
    if jobs == 1:
        done = sum(1 for _ in Campaign(task, campaign_seeds(0, runs), None, 1))
    else:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            done = sum(1 for _ in Campaign(task, campaign_seeds(0, runs), pool, 8 * jobs))
    return (done / (time.perf_counter() - started),
            (cpu_seconds() - cpu) * 1000 / done)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=1000)
    parser.add_argument("--rate-runs", type=int, default=100)
    options = parser.parse_args()
    cores = os.cpu_count() or 1
    task = task_for(PROGRAM.read_text(), noisy_world(), "sample.noisy.world.toml", "vm",
                    DEFAULT_BUDGET, PROGRAM.name)
    one, one_cpu = measure(task, options.rate_runs, 1)
    every, every_cpu = measure(task, options.rate_runs, cores)
    load = os.getloadavg()[0]  # other work on the machine takes cores from the pool
    print(f"Listing 1 on the sample world with noise on, {options.rate_runs} runs "
          f"({cores} cores, load average {load:.1f} before):")
    print(f"  1 process:   {one:6.1f} runs/s, {one_cpu:.0f} ms of CPU a run")
    print(f"  {cores} processes: {every:6.1f} runs/s ({every / one:.2f}x one process), "
          f"{every_cpu:.0f} ms of CPU a run (the pool's start-up included)")
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
