"""A cheap campaign whose success rate has a closed form, for the tests of campaigns on
local processes (tests/sim/test_campaign.py) and on a Dask cluster (test_cluster.py);
executors that make each task at once; and a campaign's two files written (these for the
sweeps' and the pictures' tests too)."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import BrokenExecutor, Executor, Future
from pathlib import Path
from typing import ParamSpec, TypeVar, cast

from rl1.compiler.campaign import Batch, Task, run_batch

DROPOUT = 0.3

# A vehicle 30 cm from a wall reads it with sensor A, except when the echo drops out
# (chance DROPOUT) and the reading is the sensor's range, 100: then the program steers
# by 2048 tenths, out of (STX)'s range, a fault at line 4. Nothing else is drawn.
WALL_PROGRAM = """\
A=(ULT A)-99; ?A>#90
(END)
:90 B=A<11
(STX B)
"""
WALL_WORLD = f"""\
[floor]
size = [1000, 1000]
[start]
x = 500.0
y = 500.0
[[walls]]
name = "ahead"
points = [[570, 0], [580, 0], [580, 1000], [570, 1000]]
[noise]
start_cm = 0
start_deg = 0
ultrasonic_cm = 0
ultrasonic_dropout = {DROPOUT}
"""


def campaign_files(folder: Path, name: str, program: str, world: str) -> tuple[Path, Path]:
    """`name`.rob holding `program` and `name`.world.toml holding `world`, in `folder`."""
    program_file, world_file = folder / f"{name}.rob", folder / f"{name}.world.toml"
    program_file.write_text(program)
    world_file.write_text(world)
    return program_file, world_file


P = ParamSpec("P")
T = TypeVar("T")


class Lost(Exception):
    """A task lost with its worker, as a Dask cluster's KilledWorker says it."""


class Instant(Executor):
    """The Executor interface, making each task at once, as if it took no time (so the
    campaign's tasks soon reach MOST_RUNS_A_TASK runs), and noting each task's seeds and
    sweep point; those of the run of `losing` it fails, its first `losses` times, as a
    Dask cluster's KilledWorker does when the task's worker died."""

    def __init__(self, losing: int | None = None, losses: int = 0) -> None:
        self.submitted: list[tuple[int, ...]] = []
        self.points: list[tuple[tuple[str, float], ...]] = []
        self.losing = losing
        self.losses = losses

    def submit(self, fn: Callable[P, T], /, *args: P.args, **kwargs: P.kwargs) -> Future[T]:
        task, seeds = args
        assert isinstance(task, Task) and isinstance(seeds, tuple)
        self.submitted.append(seeds)
        self.points.append(task.offsets)
        future: Future[T] = Future()
        if self.losing in seeds and self.losses > 0:
            self.losses -= 1
            future.set_exception(Lost(f"the worker of seeds {seeds} died"))
        else:
            future.set_result(cast(T, Batch(run_batch(task, seeds).records, 0.0)))
        return future

    def made(self, seed: int) -> int:
        """How many times the run of `seed` was submitted."""
        return sum(seed in seeds for seeds in self.submitted)


class BrokenAfter(Executor):
    """An executor that makes its first `runs` submissions at once, then refuses every
    other as a pool whose worker died does."""

    def __init__(self, runs: int) -> None:
        self.left = runs

    def submit(self, fn: Callable[P, T], /, *args: P.args, **kwargs: P.kwargs) -> Future[T]:
        if self.left == 0:
            raise BrokenExecutor("a worker process ended abruptly")
        self.left -= 1
        future: Future[T] = Future()
        future.set_result(fn(*args, **kwargs))
        return future
