"""`rl1c sim FILE --world W --runs N`: a campaign (compiler/campaign.py), the program run
over N seeds on local processes or a Dask cluster (compiler/executors.py), each run a
JSON line (`--out FILE`) as it finishes in seed order, progress on standard error, and a
summary: the success rate with its 95 % Wilson interval and the failures grouped by kind
and source line, each with the seeds of its first runs and the `rl1c sim` command that
replays one. Ctrl-C or SIGTERM stops it with the runs finished kept, written and summed
up."""

from __future__ import annotations

import contextlib
import json
import os
import shlex
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field, replace
from types import FrameType
from typing import IO

import click

from rl1.compiler.campaign import (
    Campaign,
    Record,
    Tally,
    Task,
    Timing,
    campaign_seeds,
    noiseless,
    task_for,
    wilson,
    world_of,
)
from rl1.compiler.executors import ClusterLost, Unavailable, Workers, workers
from rl1.compiler.reporting.render import EXIT_USAGE, ColorChoice
from rl1.compiler.sweep import Axis, Point, grid, heat_map, table
from rl1.vm.defaults import DEFAULT_BUDGET, Engine
from rl1.vm.sim.campaign_render import Overlay, Run, heat_map_svg, html, svg
from rl1.vm.sim.world import World

from .command import (
    EXIT_INTERNAL,
    CommandError,
    Failure,
    message_line,
    stop_signals_handled,
)
from .running import run_file
from .streams import (
    PATH_ESCAPES,
    cannot_write,
    file_failure,
    read_ilc,
    same_file,
    write_file,
)

# What the campaign's errors, warnings and notes begin with: some are said from the
# executors' threads, where click's context (rl1c sim's own messages) is not at hand.
COMMAND_PATH = "rl1c sim"
PROGRESS_EVERY = 5.0  # s between progress lines when standard error is no terminal
REDRAW_EVERY = 0.2  # s between redraws of the progress line on a terminal
WINDOW_PER_JOB = 8  # tasks in flight per worker (a cluster: per thread), each of a few
# runs (compiler/campaign.py): enough to keep each busy, few to hold
MAX_JOBS = 1024  # processes: beyond, --scheduler (a cluster) is the way


@dataclass(frozen=True, slots=True)
class Setting:
    """A campaign as the command line gives it, for the summary and the replay command."""

    file: str
    world: str
    seed: int
    runs: int
    jobs: int
    engine: Engine
    budget: int
    scheduler: str | None = None  # a Dask cluster's, instead of `jobs` local processes
    sweep: tuple[Axis, ...] = ()  # the parameters swept (--sweep), each a campaign a point

    def rest(self, seed: int, runs: int) -> str:
        """The `rl1c sim --runs` command of the campaign's last `runs` runs, from `seed`."""
        words = ["rl1c", "sim", self.file, "--world", self.world, "--runs", str(runs),
                 "--seed", str(seed)]
        words += ["--jobs", str(self.jobs)] if self.scheduler is None else [
            "--scheduler", self.scheduler]
        return shlex.join(words + self._engine_words())

    def point(self, point: Point) -> str:
        """The `rl1c sim --runs` command of the campaign at one point of the sweep."""
        words = ["rl1c", "sim", self.file, "--world", self.world, "--runs", str(self.runs),
                 "--seed", str(self.seed)]
        for axis, (_, offset) in zip(self.sweep, point, strict=True):
            words += ["--sweep", axis.words(offset)]
        return shlex.join(words + self._engine_words())

    def _engine_words(self) -> list[str]:
        words = []
        if self.engine != "vm":
            words += ["--engine", self.engine]
        if self.budget != DEFAULT_BUDGET:
            words += ["--budget", str(self.budget)]
        return words

    def replay(self, seed: int, point: Point = ()) -> str:
        """The `rl1c sim` command that makes the run of `seed` alone (at `point` of the
        sweep)."""
        words = ["rl1c", "sim", self.file, "--world", self.world, "--seed", str(seed)]
        for axis, (_, offset) in zip(self.sweep, point, strict=False):
            words += ["--sweep", axis.words(offset)]
        return shlex.join(words + self._engine_words())


class Stopped(Exception):
    """Ctrl-C (SIGINT) or SIGTERM: the campaign stops and keeps what it ran; the exit
    status is 128 + the signal's number, as shells report a program a signal stopped."""

    def __init__(self, status: int) -> None:
        super().__init__(status)
        self.status = status


class Stopping:
    """While in effect, SIGINT and SIGTERM stop the campaign by raising Stopped, but
    never while a run is being kept (`keeping`): then after it, so that the JSON lines
    and the summary always count the same runs."""

    def __init__(self) -> None:
        self._keeping = False
        self._pending: int | None = None

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self._keeping:
            self._pending = signum
        else:
            raise Stopped(128 + signum)

    @contextmanager
    def in_effect(self) -> Iterator[None]:
        with stop_signals_handled(self._handle):
            yield

    @contextmanager
    def keeping(self) -> Iterator[None]:
        self._keeping = True
        try:
            yield
        finally:
            self._keeping = False
        if self._pending is not None:
            raise Stopped(128 + self._pending)


@contextmanager
def _workers(setting: Setting, progress: Progress) -> Iterator[Workers]:
    """The campaign's workers (no more local processes than runs; a new pool of them when
    one dies; each worker lost said through `progress`), or the Failure that says why
    there are none."""
    try:
        with workers(min(setting.jobs, setting.runs), setting.scheduler,
                     lost=lambda: progress.warn(WORKER_LOST),
                     unmanned=lambda: progress.warn(no_workers_left(setting.scheduler or ""))
                     ) as held:
            if setting.scheduler is not None and held.slots == 0:
                print(message_line(
                    COMMAND_PATH, "note", f"the scheduler at {setting.scheduler} has no "
                    f"workers yet; the runs wait for one (`dask worker {setting.scheduler}`)"),
                    file=sys.stderr)
            yield held
    except Unavailable as error:
        raise CommandError(str(error)) from None


def task_of(file: str, world: bytes, world_name: str, setting: Setting,
            color: ColorChoice) -> Task | int:
    """The campaign's task: the program checked by running the campaign's first seed in
    this process, as `rl1c sim` runs it (its errors and warnings shown once, on standard
    error); the exit status instead when it cannot run."""
    from rl1.compiler.simulation import Simulation
    from rl1.vm.sim.world import decode_world

    simulation = Simulation(decode_world(world, world_name), setting.seed)
    ran = run_file(file, simulation.device, setting.engine, setting.budget, color, "sim")
    if isinstance(ran, int):
        return ran
    program = read_ilc(file) if file.lower().endswith(".ilc") else ran.source or ""
    return task_for(program, world, world_name, setting.engine, setting.budget,
                    os.path.basename(ran.source_name))


class Progress:
    """The runs done, the success rate and the runs per second, on standard error: one
    line redrawn on a terminal, else a line every PROGRESS_EVERY seconds."""

    def __init__(self, total: int, stream: IO[str],
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.total = total
        self.stream = stream
        self.terminal = stream.isatty()
        self.clock = clock
        self.started = self.shown = clock()

    def update(self, tally: Tally) -> None:
        now = self.clock()
        if now - self.shown < (REDRAW_EVERY if self.terminal else PROGRESS_EVERY):
            return
        self.shown = now
        rate = tally.runs / max(now - self.started, 1e-9)
        line = (f"{tally.runs}/{self.total} runs, {tally.successes} succeeded "
                f"({tally.successes / tally.runs:.1%}), {rate:.1f} runs/s")
        if self.terminal:
            width = 30
            filled = round(width * tally.runs / self.total)
            self.stream.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {line}")
        else:
            self.stream.write(line + "\n")
        self.stream.flush()

    def finish(self) -> None:
        if self.terminal:
            self.stream.write("\r\033[K")
            self.stream.flush()

    def warn(self, warning: str) -> None:
        """Say `warning` on a line of its own (the progress line is drawn again later)."""
        self.finish()
        self.stream.write(message_line(COMMAND_PATH, "warning", warning) + "\n")
        self.stream.flush()


WORKER_LOST = ("a worker process ended abruptly (killed, or out of memory); its runs and "
               "those beside it are made again, a run a task")


def no_workers_left(scheduler: str, waiting: str = "the runs") -> str:
    """What a campaign says when the cluster's last worker is gone: `waiting` (rl1c
    fuzz's searches) wait for one."""
    return (f"the Dask scheduler at {scheduler} has no workers left (killed, or out of "
            "memory: one is started again only under a nanny, `dask worker` without "
            f"--no-nanny); {waiting} wait for one (`dask worker {scheduler}`)")


SAME_RUNS = ("the world has no noise: every seed makes the same run, so {counted} "
             "counted N times; give the world `noise = true`, a [noise] table "
             "(spec/simulator.md, \"Noise\") or a [vary] table to vary the runs")


def summary(setting: Setting, tally: Tally, task: Task, stopped: bool) -> str:
    """The campaign's summary for people."""
    lines = [f"{tally.runs} run{'s' if tally.runs != 1 else ''} of {setting.file} on "
             f"{setting.world}, seeds {setting.seed}.."
             f"{setting.seed + setting.runs - 1}"
             + (f" (stopped after {tally.runs} of {setting.runs})" if stopped else "")]
    if noiseless(task):
        lines.append(SAME_RUNS.format(counted="this is one outcome"))
    if tally.runs == 0:
        return "\n".join(lines) + "\n"
    low, high = wilson(tally.successes, tally.runs)
    lines.append(f"success: {tally.successes} of {tally.runs}, "
                 f"{tally.successes / tally.runs:.1%} (95% Wilson interval "
                 f"{low:.1%}..{high:.1%}); a success ends normally"
                 + (" and meets the world's goal" if world_of(task).goal is not None else ""))
    failures = tally.failures()
    if failures:
        lines.append("failures by kind and source line:")
    for (outcome, line, detail), group in failures:
        where = "" if line is None else f" at line {line}"
        what = f" ({detail})" if detail else ""
        seeds = ", ".join(map(str, group.seeds)) + (", ..." if group.count > len(group.seeds)
                                                    else "")
        lines.append(f"  {group.count:>6}  {outcome}{where}{what}: seeds {seeds}")
        lines.append(f"          replay: {setting.replay(group.seeds[0])}")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True, slots=True)
class Pictures:
    """The pictures of a campaign the command line asks for (--svg, --html)."""

    svg: str | None
    html: str | None
    force: bool

    @property
    def wanted(self) -> bool:
        return self.svg is not None or self.html is not None


NO_PICTURES = Pictures(None, None, False)
PATH_POINTS = 64  # of each run's path that a record carries for the pictures


def _open_out(out: str | None, inputs: tuple[str, str]) -> IO[str] | None:
    """The file of the JSON lines, never an input, written as the runs finish (so that it
    can be followed while the campaign runs)."""
    if out is None:
        return None
    if out == "-":
        return sys.stdout
    for role, name in zip(("program", "world file"), inputs, strict=True):
        if same_file(name, out):
            raise click.UsageError(f"--out `{out}` is the {role} itself: give another "
                                   "path for the runs' JSON lines")
    try:
        return open(out, "w", encoding="utf-8")  # closed by run_campaign
    except OSError as error:
        raise _unwritten(out, error) from None


def _unwritten(out: str, error: OSError) -> Failure:
    return file_failure(cannot_write(out, "campaign file", error))


class _LineUnwritten(Exception):
    """A run's JSON line that could not be written (a full disk): the file holds the whole
    lines before it, its first `whole` bytes."""

    def __init__(self, error: OSError, whole: int) -> None:
        super().__init__(error)
        self.error, self.whole = error, whole


def run_campaign(file: str, world: bytes, world_name: str, setting: Setting, out: str | None,
                 color: ColorChoice, pictures: Pictures = NO_PICTURES) -> int:
    """The campaign `setting` of the program `file` on the world file `world` (its bytes,
    named `world_name`), and its `pictures`; its exit status: 0 when it ran to its end,
    whatever the rate."""
    try:
        seeds = campaign_seeds(setting.seed, setting.runs)
    except ValueError as error:
        raise click.UsageError(f"--seed and --runs: {error}; give a smaller --seed or "
                               "fewer --runs") from None
    if setting.jobs > MAX_JOBS:
        raise click.UsageError(f"--jobs {setting.jobs}: at most {MAX_JOBS} processes on "
                               "one machine")
    task = task_of(file, world, world_name, setting, color)
    if isinstance(task, int):
        return task
    if pictures.wanted:  # their targets checked by sim.refuse_picture_targets
        task = replace(task, path_points=PATH_POINTS)
    points = grid(setting.sweep)
    progress = Progress(setting.runs * len(points), sys.stderr)
    held = ExitStack()  # the workers: a cluster is reached before --out replaces a file
    current = held.enter_context(_workers(setting, progress))
    try:
        lines = _open_out(out, (file, setting.world))
    except BaseException:
        held.close()
        raise
    report = sys.stderr if out == "-" else sys.stdout
    keeper = Keeper(setting.runs, points, lines, Overlay() if pictures.wanted else None)
    timing = Timing()  # carried from point to point: they run one program on near worlds
    status = 0
    lost: ClusterLost | None = None
    stopping = Stopping()
    try:
        with stopping.in_effect(), held:  # the workers end while a signal only stops
            while status == 0 and not keeper.done:
                left = range(setting.seed + keeper.tally.runs, seeds.stop)
                status = _make_runs(replace(task, offsets=keeper.point), left, current,
                                    keeper, progress, stopping, timing)
    except Stopped as stop:  # again, while the workers end their runs
        status = stop.status
    except ClusterLost as error:
        status, lost = EXIT_USAGE, error
    except _LineUnwritten as unwritten:
        if lines is None or lines is sys.stdout:  # said as any output's failure: a pipe
            raise unwritten.error from None  # closed by `| head` ends quietly
        with contextlib.suppress(OSError):  # its flush fails again
            lines.close()
        with contextlib.suppress(OSError):  # shrinking a file needs no room
            os.truncate(str(out), unwritten.whole)  # no half line left at its end
        raise _unwritten(str(out), unwritten.error) from None
    finally:
        progress.finish()
        if lines is not None and lines is not sys.stdout:
            lines.close()
    tally = keeper.tally
    said = (sweep_summary(setting, keeper, task, stopped=status != 0) if setting.sweep else
            summary(setting, tally, task, stopped=status != 0))
    report.write(said)
    report.flush()
    if keeper.overlay is not None:
        _draw(pictures, keeper.overlay, keeper.tallies, setting, world_of(task), said)
    next_seed = setting.seed + tally.runs
    rest = setting.rest(next_seed, setting.runs - tally.runs)
    if status == EXIT_INTERNAL:
        print(message_line(
            COMMAND_PATH, "error", f"the run of seed {next_seed} ended its worker each "
            f"time it was made: replay it alone ({setting.replay(next_seed, keeper.point)}), "
            "and if rl1c crashed, report it; the runs before it are kept"
            + ("" if setting.sweep else "; to go on after it: "
               + setting.rest(next_seed + 1, setting.runs - tally.runs - 1))),
            file=sys.stderr)
    elif status:
        kept = ("the runs finished are kept" + ("" if out is None else f" in {out}") + (
            "; to go on, run the sweep again (each point makes the same runs)"
            if setting.sweep else "; to go on, run the seeds left: " + rest))
        print("rl1c: interrupted: " + kept if lost is None
              else message_line(COMMAND_PATH, "error", f"{lost}: {kept}"), file=sys.stderr)
    return status

def _make_runs(task: Task, seeds: range, held: Workers, keeper: Keeper,
               progress: Progress, stopping: Stopping, timing: Timing) -> int:
    """Make the runs of `seeds` on `held`, keeping each, their tasks sized by `timing`
    (which takes their times); 0, the status of a signal that stopped them, or
    EXIT_INTERNAL when a run was lost with its worker each time it was made.
    ClusterLost when a cluster's scheduler was lost, after keeping the runs finished
    before the first lost."""
    runs = Campaign(task, seeds, held.executor, WINDOW_PER_JOB * max(held.slots, 1),
                    held.lost, timing)
    ending: tuple[type[BaseException], ...] = (Stopped, ClusterLost, *held.lost)
    try:
        for record in runs:
            with stopping.keeping():
                keeper.keep(record)
            progress.update(keeper.total)
    except ending as stop:
        with stopping.keeping():
            for record in runs.salvage():
                keeper.keep(record)
        match stop:
            case Stopped():
                return stop.status
            case ClusterLost():
                raise
        return EXIT_INTERNAL
    return 0


@dataclass(slots=True)
class Keeper:
    """Where each run's record goes, in the campaign's order: its JSON line, the tally of
    its point of the sweep (of the campaign, without one) and of every run, and the
    pictures' overlay. A point's tally is begun when the one before it is whole."""

    runs: int  # at each point
    points: list[Point]
    lines: IO[str] | None
    overlay: Overlay | None
    tallies: list[Tally] = field(default_factory=lambda: [Tally()])
    total: Tally = field(default_factory=Tally)
    whole: int = 0  # bytes of the JSON lines written whole, in a file

    @property
    def tally(self) -> Tally:
        return self.tallies[-1]

    @property
    def point(self) -> Point:
        return self.points[len(self.tallies) - 1]

    @property
    def done(self) -> bool:
        return len(self.tallies) == len(self.points) and self.tally.runs == self.runs

    def keep(self, record: Record) -> None:
        self.tally.add(record)
        self.total.add(record)
        if self.lines is not None:
            # ASCII (json.dumps escapes the rest): its length is its bytes, counted, not
            # asked of the file, which may be a pipe (--out FIFO) that cannot tell
            line = json.dumps(record.to_json(), separators=(",", ":")) + "\n"
            try:
                self.lines.write(line)
                self.lines.flush()  # a line is whole on disk when the campaign is stopped
            except OSError as error:
                raise _LineUnwritten(error, self.whole) from None
            self.whole += len(line)
        if self.overlay is not None:
            self.overlay.add(Run(record.seed, record.path, record.pose[:2],
                                 None if record.success else record.safety or record.outcome,
                                 record.line))
        if self.tally.runs == self.runs and len(self.tallies) < len(self.points):
            self.tallies.append(Tally())


def _draw(pictures: Pictures, overlay: Overlay, tallies: list[Tally], setting: Setting,
          world: World, said: str) -> None:
    """Write the campaign's pictures: the runs overlaid on the world, and for a sweep
    the heat map of its success rates (the SVG then is the heat map alone)."""
    title = (f"{os.path.basename(setting.file)} on {os.path.basename(setting.world)}: "
             f"{overlay.runs:,} runs")
    moved = dict.fromkeys([*(axis.key for axis in setting.sweep),
                           *(varied.key for varied in world.varied)])
    drawn = [svg(world, overlay, title, list(moved))]
    if setting.sweep:
        rows, *columns = setting.sweep
        drawn.insert(0, heat_map_svg(
            f"success rate at each point, {setting.runs} runs a point",
            (rows.key, rows.offsets()),
            (columns[0].key, columns[0].offsets()) if columns else ("", [0.0]),
            [(tally.successes, tally.runs) for tally in tallies]))
    if pictures.svg is not None:
        write_file(pictures.svg, drawn[0].encode("utf-8", PATH_ESCAPES), force=pictures.force,
                   role="SVG file")
    if pictures.html is not None:
        write_file(pictures.html, html(title, drawn, said).encode("utf-8", PATH_ESCAPES),
                   force=pictures.force, role="HTML file")


def sweep_summary(setting: Setting, keeper: Keeper, task: Task, stopped: bool) -> str:
    """A sweep's summary for people: the success rate at each point, and a heat map of
    two parameters."""
    runs = keeper.total.runs
    lines = [f"{runs} run{'s' if runs != 1 else ''} of {setting.file} on {setting.world}: "
             f"seeds {setting.seed}..{setting.seed + setting.runs - 1} at each of "
             f"{len(keeper.points)} points, the parameters moved from the world's values"
             + (f" (stopped at point {len(keeper.tallies)})" if stopped else ""),
             *([SAME_RUNS.format(counted="each point is one outcome")]
               if noiseless(task) else []),
             table(setting.sweep, keeper.points, keeper.tallies).rstrip("\n")]
    if len(setting.sweep) == 2:
        lines.append(heat_map(setting.sweep, keeper.tallies).rstrip("\n"))
    made = [(tally.successes / tally.runs, i) for i, tally in enumerate(keeper.tallies)
            if tally.runs]
    if made:
        weakest = keeper.points[min(made)[1]]
        lines.append("the weakest point's campaign alone, its failures grouped with the "
                     f"commands that replay them: {setting.point(weakest)}")
    return "\n".join(lines) + "\n"

