"""A campaign: one program run on one world over many seeds, to answer "how often does it
succeed, and how does it fail" (spec/simulator.md, "Campaigns").

Each run is a plain function of the task (the program as source text or .ilc bytes, the
world file's bytes, the engine and budget) and its seed, `run_one`, and is the run
`rl1c sim FILE --world W --seed SEED` makes (both go through compiler/simulation.py).
The runs go to any `concurrent.futures.Executor` (local processes or a Dask cluster:
compiler/executors.py), each task carrying the program and the world, so a worker
needs no files. `Campaign` yields the records in seed order whatever the executor, with
at most `window` runs in flight, so the output is the same for any number of workers and
memory stays flat; `Tally` keeps only counts and the first few seeds of each failure
group, never the records.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Iterable, Iterator, Sequence
from concurrent.futures import Executor, Future
from dataclasses import dataclass, field
from functools import lru_cache
from itertools import islice
from typing import Any

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.frontend.collector import FullCollections
from rl1.compiler.runner import Finished, run
from rl1.compiler.simulation import Simulation, run_status
from rl1.vm.defaults import Engine
from rl1.vm.sim.motion import Pose, heading_degrees
from rl1.vm.sim.world import NOISELESS, World, decode_world

MAX_SEED = 2**32 - 1  # `rl1c sim --seed`'s range
Z_95 = 1.959963984540054  # the normal quantile of 0.975: a two-sided 95 % interval
SEEDS_KEPT = 3  # of each failure group, the first seeds


def campaign_seeds(start: int, runs: int) -> range:
    """The seeds of a campaign of `runs` runs from seed `start`: start, start + 1, ...
    (each names the `rl1c sim --seed` run it is). ValueError past the seeds' range."""
    if runs < 1 or start < 0 or start + runs - 1 > MAX_SEED:
        raise ValueError(f"the seeds {start}..{start + runs - 1} leave 0..{MAX_SEED}")
    return range(start, start + runs)


@dataclass(frozen=True, slots=True)
class Task:
    """What every run of a campaign shares, sent whole to each worker: the program (RL/I
    source, named `source_name` in the compiled code, or the bytes of an .ilc file) and
    the world file's bytes (named `world_name` in its errors)."""

    program: str | bytes
    world: bytes
    world_name: str
    engine: Engine = "vm"
    budget: int = 0
    source_name: str = "program.rob"
    offsets: tuple[tuple[str, float], ...] = ()  # a sweep's point: parameters moved
    path_points: int = 0  # the most points of each run's path a record keeps (pictures)


def task_for(program: str | bytes, world: bytes, world_name: str, engine: Engine,
             budget: int, source_name: str, path_points: int = 0) -> Task:
    """The task of a campaign of `program`: RL/I source is compiled here once, as `rl1c
    sim` compiles it for its run, for the VMs (the interpreter runs the source). The
    source must compile."""
    if isinstance(program, str) and engine != "ast":
        compiled = compile_text(program, source_name).output
        if compiled is None:
            raise ValueError("the program has errors: a campaign runs only a program "
                             "that compiles")
        program = compiled
    return Task(program, world, world_name, engine, budget, source_name,
                path_points=path_points)


@dataclass(frozen=True, slots=True)
class Record:
    """One run of a campaign: its seed and how it ended. `outcome` is `rl1c sim`'s
    status code (ok, goal-missed, or the fault's kind) and `exit_status` its exit status;
    a success is status 0. `missed` names the goal's parts missed (each `part "name"`,
    as the report titles it), `safety` the kind of a safety stop; `device_time` is when
    the program ended (ms), `pose` where the vehicle was at the end (after any run-on).
    `varied` gives the value in the run of each parameter drawn ([vary]) or swept, and
    `path` where the vehicle went, thinned, when the task asks for it (never in JSON)."""

    seed: int
    outcome: str
    exit_status: int
    line: int | None
    message: str
    safety: str | None
    goal_met: bool | None
    missed: tuple[str, ...]
    device_time: int
    pose: tuple[float, float, float]
    instructions: int | None
    varied: tuple[tuple[str, float], ...] = ()
    path: tuple[tuple[float, float], ...] = ()

    @property
    def success(self) -> bool:
        return self.exit_status == 0

    def to_json(self) -> dict[str, Any]:
        return {"seed": self.seed, "success": self.success, "outcome": self.outcome,
                "exit_status": self.exit_status, "line": self.line,
                "message": self.message, "safety": self.safety,
                "goal": None if self.goal_met is None else {
                    "met": self.goal_met, "missed": list(self.missed)},
                "device_time": self.device_time, "pose": list(self.pose),
                "instructions": self.instructions,
                **({"varied": dict(self.varied)} if self.varied else {})}


COLLECT_EVERY = 64  # runs between full collections of a worker's garbage
# A worker compiles or interprets source each run: without a full collection now and
# then (frontend/collector.py says why) it would grow without end.
_collections = FullCollections(COLLECT_EVERY)


@lru_cache(maxsize=4)
def _decoded(data: bytes, name: str) -> World:
    return decode_world(data, name)


def world_of(task: Task) -> World:
    """The world of `task`, decoded once per process (every task carries the same bytes)."""
    return _decoded(task.world, task.world_name)


def run_one(task: Task, seed: int) -> Record:
    """The run of `task` with `seed`, as `rl1c sim --seed SEED` makes it. The program
    must compile (a campaign checks it once before its runs)."""
    _collections.count()
    world, varied = run_world(world_of(task), task.offsets, seed)
    simulation = Simulation(world, seed)
    device = simulation.device
    finished = run(task.program, device, engine=task.engine, budget=task.budget,
                   source_name=task.source_name)
    if not isinstance(finished, Finished):
        raise ValueError("the program has errors: a campaign runs only a program that compiles")
    result = finished.result
    ending = simulation.end(result)
    status = run_status(result, ending.verdict)
    verdict = ending.verdict
    pose = device.sim.pose
    return Record(
        seed=seed, outcome=status["code"], exit_status=status["exit_status"],
        line=status["line"], message=status["message"],
        safety=None if device.fault is None else device.fault.kind,
        goal_met=None if verdict is None else verdict.met,
        missed=() if verdict is None else tuple(part.title() for part in verdict.missed()),
        device_time=round(ending.ended_at * 1000),
        pose=(round(pose.x, 2), round(pose.y, 2), heading_degrees(pose.heading, 2)),
        instructions=finished.instructions, varied=tuple(varied.items()),
        path=thinned(device.sim.track, task.path_points))


def run_world(world: World, offsets: Iterable[tuple[str, float]],
              seed: int) -> tuple[World, dict[str, float]]:
    """The world of the run of `seed` at a sweep's point (`offsets`: none outside a
    sweep): the parameters swept moved, then those of [vary] drawn; and the value in
    the run of each parameter swept or drawn."""
    moved = dict(offsets)
    world, drawn = world.moved(moved).drawn(seed)
    return world, {key: world.parameter(key).value for key in moved} | drawn


def thinned(track: Sequence[tuple[float, Pose]], most: int) -> tuple[tuple[float, float], ...]:
    """At most `most` points of `track` (none when 0), evenly spread, its first and last
    kept, each to the millimetre."""
    if most < 2 or not track:
        return ()
    every = max(1, math.ceil((len(track) - 1) / (most - 1)))
    kept = [*track[:-1:every], track[-1]]
    return tuple((round(pose.x, 1), round(pose.y, 1)) for _, pose in kept)


def noiseless(task: Task) -> bool:
    """Whether every run of `task` is the same run: its world has no noise and draws
    nothing ([vary]), the only things a seed changes."""
    world = world_of(task)
    return world.noise == NOISELESS and not world.varied


RESUBMISSIONS = 2  # of a run lost with its worker: more, and the run may be what kills them
TASK_SECONDS = 0.5  # of runs a task makes: a task's cost on a cluster (about 4.4 ms of
# CPU, bench/campaign.py) then weighs little, and a stopped campaign loses little
MOST_RUNS_A_TASK = 64  # so that a window of tasks holds at most 64 records a task


@dataclass(frozen=True, slots=True)
class Batch:
    """What a task brings back: the records of its seeds, in their order, and the
    seconds it took to make them (which size the tasks that follow)."""

    records: tuple[Record, ...]
    seconds: float


def run_batch(task: Task, seeds: tuple[int, ...]) -> Batch:
    """The runs of `task` with `seeds`, one after the other: a campaign's task."""
    started = time.perf_counter()
    records = tuple(run_one(task, seed) for seed in seeds)
    return Batch(records, time.perf_counter() - started)


def runs_a_task(runs: int, seconds: float) -> int:
    """How many runs the next task makes, when `runs` runs have taken `seconds` so far:
    as many as fill TASK_SECONDS, from 1 (also while none has been timed) to
    MOST_RUNS_A_TASK. A run's cost varies with its seed, so the mean of all is used."""
    if runs == 0 or seconds * MOST_RUNS_A_TASK <= TASK_SECONDS * runs:
        return 1 if runs == 0 else MOST_RUNS_A_TASK
    return max(1, int(TASK_SECONDS * runs / seconds))


@dataclass(slots=True)
class Timing:
    """The runs timed so far and the seconds they took, which size the tasks that
    follow. Campaigns of one program on near worlds (a sweep's points) share one, so that
    each after the first starts with tasks of the right size, not of one run."""

    runs: int = 0
    seconds: float = 0.0

    def add(self, batch: Batch) -> None:
        self.runs += len(batch.records)
        self.seconds += batch.seconds

    def runs_a_task(self) -> int:
        return runs_a_task(self.runs, self.seconds)


@dataclass(slots=True)
class _Part:
    """Runs submitted as one task: their seeds, the task's future, how many of its
    records the campaign has yielded, and how many times these runs have been made."""

    seeds: tuple[int, ...]
    future: Future[Batch]
    tries: int = 1
    taken: int = 0


class Campaign:
    """The runs of `task` over `seeds` on `executor` (in this process when None), as an
    iterator of their records in seed order. The runs go in tasks of several seeds each
    (`runs_a_task`: about TASK_SECONDS of runs), with at most `window` tasks submitted
    and not yet yielded whole. A task that fails with an error of `lost` (its worker
    died: a Dask cluster's KilledWorker, a local pool's BrokenProcessPool) is submitted
    again a run a task once the runs before it are yielded, so that a run that kills its
    worker is told from those beside it; each run is made at most 1 + RESUBMISSIONS
    times. `salvage` ends it early, keeping the runs already finished that follow the
    last yielded without a gap. `timing` holds the runs timed before (a sweep's earlier
    points), and takes this campaign's."""

    def __init__(self, task: Task, seeds: Iterable[int], executor: Executor | None,
                 window: int, lost: tuple[type[BaseException], ...] = (),
                 timing: Timing | None = None) -> None:
        self._task = task
        self._seeds = iter(seeds)
        self._executor = executor
        self._window = window
        self._lost = lost
        self._pending: deque[_Part] = deque()
        self._timing = Timing() if timing is None else timing

    def __iter__(self) -> Iterator[Record]:
        if self._executor is None:
            for seed in self._seeds:
                yield run_one(self._task, seed)
            return
        self._fill()
        while self._pending:
            part, records = self._first_records()
            # Counted before it is yielded, each record, so that a signal between two
            # instructions finds it either yielded or salvaged, never both or neither.
            while part.taken < len(records):
                record = records[part.taken]
                part.taken += 1
                yield record
            self._pending.popleft()
            self._fill()  # after: a broken pool refuses it, and salvage finds the rest

    def _fill(self) -> None:
        while len(self._pending) < self._window:
            seeds = tuple(islice(self._seeds, self._timing.runs_a_task()))
            if not seeds:
                return
            self._pending.append(_Part(seeds, self._submit(seeds)))

    def _submit(self, seeds: tuple[int, ...]) -> Future[Batch]:
        assert self._executor is not None
        return self._executor.submit(run_batch, self._task, seeds)

    def _first_records(self) -> tuple[_Part, tuple[Record, ...]]:
        """The first task in flight and its records; lost with its worker, its runs are
        submitted again in its place, a task each."""
        while True:
            part = self._pending[0]
            try:
                batch = part.future.result()
            except self._lost:
                if part.tries > RESUBMISSIONS:
                    raise
                again = [_Part((seed,), self._submit((seed,)), part.tries + 1)
                         for seed in part.seeds]
                # One assignment: a signal finds the queue before or after, whole.
                self._pending = deque([*again, *islice(self._pending, 1, None)])
                continue
            self._timing.add(batch)
            return part, batch.records

    def salvage(self) -> list[Record]:
        """Stop: cancel the runs not yet made, and return the finished runs that follow
        the last yielded in seed order without a gap (so that the records of a stopped
        campaign are its first seeds, and the next campaign can start where it ended)."""
        finished: list[Record] = []
        gap = False
        for part in self._pending:
            future = part.future
            gap = gap or not future.done() or future.cancelled() \
                or future.exception() is not None
            if gap:
                future.cancel()  # a task already started ends on its own, unread
            else:
                finished.extend(future.result().records[part.taken:])
        self._pending.clear()
        return finished


def wilson(successes: int, runs: int, z: float = Z_95) -> tuple[float, float]:
    """The Wilson score interval of a success rate of `successes` in `runs` (runs > 0),
    at the normal quantile `z` (default: 95 %)."""
    rate = successes / runs
    z2 = z * z
    centre = (rate + z2 / (2 * runs)) / (1 + z2 / runs)
    half = z / (1 + z2 / runs) * math.sqrt(rate * (1 - rate) / runs + z2 / (4 * runs * runs))
    # It always holds the rate; rounding alone would put 0 of n a hair above 0.
    return max(0.0, min(centre - half, rate)), min(1.0, max(centre + half, rate))


@dataclass(slots=True)
class Group:
    """The failures of one kind at one place: how many, and the first seeds."""

    count: int = 0
    seeds: list[int] = field(default_factory=list)


GroupKey = tuple[str, int | None, str]  # outcome, source line, what: a safety stop, parts missed


def group_key(record: Record) -> GroupKey:
    """A failure's group: its outcome and line, and the kind of a safety stop or, when
    the program ended, the goal's parts it missed."""
    detail = "; ".join(record.missed) if record.outcome == "goal-missed" else record.safety
    return record.outcome, record.line, detail or ""


@dataclass(slots=True)
class Tally:
    """What a campaign keeps of its records: counts, and the first SEEDS_KEPT seeds of
    each failure group (the groups are bounded by the outcomes, lines and goal parts)."""

    runs: int = 0
    successes: int = 0
    groups: dict[GroupKey, Group] = field(default_factory=dict)

    def add(self, record: Record) -> None:
        self.runs += 1
        if record.success:
            self.successes += 1
            return
        group = self.groups.setdefault(group_key(record), Group())
        group.count += 1
        if len(group.seeds) < SEEDS_KEPT:
            group.seeds.append(record.seed)

    def failures(self) -> list[tuple[GroupKey, Group]]:
        """The failure groups, the most frequent first (then by outcome and line)."""
        return sorted(self.groups.items(),
                      key=lambda item: (-item[1].count, item[0][0], item[0][1] or 0,
                                        item[0][2]))
