"""A differential fuzzing campaign: generated runs on several engines until one
disagrees, then that run shrunk to a small one and written down as a reproducer.

Runs come from `strategies.runs()`; Hypothesis' `find` generates them and, on the first
disagreement, shrinks the run to the smallest it can find that still disagrees (the
disagreement may change on the way: it is the smallest run that shows one), for at most
SHRINK_ATTEMPTS runs, a bound in runs rather than seconds, so that a seed gives the same
reproducer on a loaded machine as on an idle one. `judge` in differential.py decides
what disagrees (spec/optimization.md). A program on which an engine ends the process it
runs in (the C VM's crash) ends a worker: the searches lost with it run again with each
program judged in a process of its own, where that program is a finding, shrunk as any.
"""

from __future__ import annotations

import contextlib
import gc
import itertools
import json
import math
import os
import re
import shlex
import shutil
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, wait
from dataclasses import dataclass, field, replace
from random import Random
from typing import Any

from hypothesis import HealthCheck, Phase, find, settings
from hypothesis.errors import NoSuchExample
from hypothesis.internal.conjecture import providers
from hypothesis.internal.constants_ast import Constants

from rl1.compiler.analysis import analyze
from rl1.compiler.backend.driver import OPTIMIZATION_LEVELS
from rl1.compiler.backend.lower import lower
from rl1.compiler.backend.optimize import optimize
from rl1.compiler.differential import (
    AstEngine,
    BatchEngine,
    CEngine,
    Engine,
    ExecEngine,
    Verdict,
    VmEngine,
    compiled,
    engine_named,
    judge,
    judge_apart,
    signature,
)
from rl1.compiler.files import SourceError, read_bounded, write_atomically
from rl1.compiler.frontend.source import read_source
from rl1.compiler.reduce import Case, NotInteresting, reduce, script_text
from rl1.compiler.runner import MAX_SCRIPT_BYTES
from rl1.compiler.strategies import Run, runs
from rl1.vm import isa
from rl1.vm.config import ConfigError, read_document
from rl1.vm.faults import MAX_BUDGET
from rl1.vm.language import LOST_LINE_RULES
from rl1.vm.sensor_script import ScriptError, parse_script

# Hypothesis' shrinking stops after trying so many runs, with the smallest so far (on a
# planted shift bug it went on for 1,100 to 1,700 runs to save a character or two, which
# deleting lines and statements then does in far fewer).
SHRINK_ATTEMPTS = 500
# Then compiler/reduce.py's passes, for at most so many runs (38 on that bug).
REDUCE_TESTS = 500
# Programs per search. Hypothesis' runner keeps what it learnt of every run it generated
# (about 130 KB each) until the search ends, so a long campaign is many short searches,
# each seeded from --seed, with their garbage collected in between; and the searches are
# what processes share, so that a campaign of 1,000 keeps ten of them busy.
BATCH = 100
SOURCE = "program.rob"
SCRIPT = "program.sensors.json"
ENGINES = "engines.json"  # the engines a reproducer names, and the budget
MAX_ENGINES_BYTES = 2**20


@dataclass(frozen=True)
class Finding:
    """The smallest run found that disagrees, and every engine's run of it."""

    case: Run
    verdict: Verdict

    @property
    def signature(self) -> str:
        return signature(self.verdict)


@dataclass(frozen=True)
class Search:
    """One search of a campaign, what a worker is sent: up to `size` programs generated
    from `seed` (a Hypothesis search, then another from a seed drawn from it when one
    ends early on a finding that `keep_going` goes past), judged on `engines`. Its
    programs depend on nothing else, so a campaign's programs are the same whatever
    runs its searches, and however many at once."""

    index: int
    seed: int
    size: int
    engines: tuple[Engine, ...]
    budget: int
    keep_going: bool = False
    deadline: float | None = None  # time.time() after which it generates no program
    channel: str | None = None  # the campaign's Channel folder, on this machine
    corpus: tuple[Run, ...] = ()  # runs judged as they are, before any generated
    statistics: bool = False  # whether to gather what the programs did
    # Each program judged in a process of its own (judge_apart): a search run again after
    # its worker died, so that a program that ends its process is told from the others.
    apart: bool = False


@dataclass
class Statistics:
    """What a campaign's programs did, as `rl1c fuzz --format json` gives it
    (spec/optimization.md, section 5): how the reference's runs ended, by status code;
    the lost lines that sent them to a handler; the instructions each VM engine executed,
    by opcode; and the programs in which each optimizer pass changed the IR at -O2."""

    endings: Counter[str] = field(default_factory=Counter)
    handler_jumps: int = 0
    opcodes: dict[str, Counter[str]] = field(default_factory=dict)
    passes: Counter[str] = field(default_factory=Counter)

    def add(self, case: Run, verdict: Verdict) -> None:
        observations = verdict.observations
        reference = next(iter(observations.values()))  # the first engine that ran it
        match reference.ending():
            case {"code": str(code)}:
                self.endings[code] += 1
        self.handler_jumps += sum(
            1 for entry in reference.commands()
            if entry.get("call") == LOST and entry.get("args", [None])[0] in JUMPING_MODES)
        for name, observation in observations.items():
            if observation.opcodes is not None:
                self.opcodes.setdefault(name, Counter()).update(observation.opcodes)
        fired: set[str] = set()
        optimize(lower(analyze(case.source).program), max(OPTIMIZATION_LEVELS),
                 fired=fired.add)
        self.passes.update(fired)

    def merge(self, other: Statistics) -> None:
        self.endings.update(other.endings)
        self.handler_jumps += other.handler_jumps
        for name, opcodes in other.opcodes.items():
            self.opcodes.setdefault(name, Counter()).update(opcodes)
        self.passes.update(other.passes)

    def to_json(self) -> dict[str, Any]:
        return {"endings": dict(sorted(self.endings.items())),
                "handler_jumps": self.handler_jumps,
                "opcodes": {name: dict(sorted(opcodes.items()))
                            for name, opcodes in self.opcodes.items()},
                "superinstructions": {
                    name: {opcode: count for opcode, count in sorted(opcodes.items())
                           if isa.BY_NAME[opcode].minor >= isa.FUSED_MINOR}
                    for name, opcodes in self.opcodes.items()},
                "passes": dict(sorted(self.passes.items()))}


LOST = "LINE LOST"  # a trace entry's call when the device lost the guidance line
JUMPING_MODES = frozenset(rule.mode for rule in LOST_LINE_RULES)  # Table 4: 2 and 3


@dataclass
class Searched:
    """What a search found: its programs, how many of them showed each signature, and
    the smallest run of each signature (of the first only, without `keep_going`); what
    its programs did, when asked."""

    index: int
    programs: int = 0
    counts: dict[str, int] = field(default_factory=dict)
    findings: dict[str, Finding] = field(default_factory=dict)
    statistics: Statistics | None = None


@dataclass(frozen=True)
class Outcome:
    programs: int  # programs run (by every search)
    seconds: float  # the time the campaign took
    finding: Finding | None  # the first (of the search first in order), or None
    counts: dict[str, int] = field(default_factory=dict)  # programs of each signature
    findings: dict[str, Finding] = field(default_factory=dict)  # each signature's first
    stopped: bool = False  # halted (a signal) before its end
    statistics: Statistics | None = None  # what the programs did, when asked


class _Enough(BaseException):
    """The campaign's time is up, it was halted, or shrinking has tried its runs: a
    BaseException, which Hypothesis lets through at once (an Exception would be a
    failure to shrink, calling the predicate again and again)."""


@contextlib.contextmanager
def only_hypothesis_constants() -> Iterator[None]:
    """While inside, Hypothesis draws none of the literals it finds in the source of the
    modules a process has loaded. Since 6.131 it does (a twentieth of its draws pick a
    constant, half of them local), so one seed gave other programs in a process that had
    loaded other modules: a Dask worker, a wheel's rl1 (site-packages, not local) rather
    than an editable one, a command that imports more. Its own constants, the same in
    every process, are still drawn. Hypothesis has no setting for it: its private
    function is replaced, and tests/cli/test_fuzz_seeds.py holds the programs the same
    with other modules loaded, so that a Hypothesis that moves it is noticed."""
    collect = getattr(providers, "_get_local_constants", None)
    if collect is None:  # a Hypothesis before 6.131, or one that collects elsewhere
        yield
        return
    providers._get_local_constants = Constants
    providers.CONSTANTS_CACHE.cache.clear()  # what was drawn from before, locals and all
    try:
        yield
    finally:
        providers._get_local_constants = collect
        providers.CONSTANTS_CACHE.cache.clear()


HALT = "halt"  # the Channel's file naming the first search that must stop
TOLD_EVERY = 1.0  # seconds between a search's counts on the Channel


class Channel:
    """A campaign's folder on this machine, through which its searches hear when to stop
    and tell how far they are: a search reads the file `halt` (the index of the first
    search that must stop) before each program, and writes its count, and whether it is
    shrinking a finding, to `told-INDEX` every TOLD_EVERY seconds and as it starts or
    ends shrinking one. Files rather than shared memory, so that it works with any
    executor whose workers share this machine; a worker elsewhere finds no file, and its
    search runs to its end."""

    def __init__(self, folder: str | None = None) -> None:
        self.folder = folder if folder is not None else tempfile.mkdtemp(prefix="rl1-fuzz-")
        self.everything = False  # halt() stopped every search: a signal, not a finding

    def halt(self, first: int = 0) -> None:
        """Stop the searches from index `first` on (every one by default: safe in a
        signal handler, which may run in the middle of a halt after a finding)."""
        self.everything = self.everything or first == 0
        self._put(HALT, str(0 if self.everything else min(first, self.halted_from())))

    def halted_from(self) -> float:
        if self.everything:
            return 0
        try:
            with open(os.path.join(self.folder, HALT), "rb") as stream:
                return int(stream.read())
        except (OSError, ValueError):  # not halted, or a folder elsewhere
            return math.inf

    def tell(self, index: int, programs: int, shrinking: bool = False) -> None:
        self._put(f"told-{index}", f"{programs} {int(shrinking)}")

    def _put(self, name: str, text: str) -> None:
        """Replace the file `name` with `text`, whole (a reader sees the old text or the
        new); a file system that refuses it leaves the old (a search halted later,
        a progress line behind), not the campaign failed."""
        path = os.path.join(self.folder, name)
        with contextlib.suppress(OSError):
            with open(f"{path}.{os.getpid()}", "w", encoding="ascii") as stream:
                stream.write(text)
            os.replace(f"{path}.{os.getpid()}", path)

    def told(self, indexes: Iterable[int]) -> tuple[int, int]:
        """The programs the searches `indexes` last told, and how many of them said they
        were shrinking a finding."""
        programs = shrinking = 0
        for index in indexes:
            with contextlib.suppress(OSError, ValueError), \
                    open(os.path.join(self.folder, f"told-{index}"), "rb") as stream:
                ran, shrinks = map(int, stream.read().split())
                programs, shrinking = programs + ran, shrinking + shrinks
        return programs, shrinking

    def close(self) -> None:
        shutil.rmtree(self.folder, ignore_errors=True)


def search(task: Search, progress: Callable[[int, bool], None] | None = None) -> Searched:
    """Run the search `task`: Hypothesis searches of its programs, each shrinking the
    first run that disagrees; without `keep_going` the search ends there, with it a run
    of a signature found already counts and the search goes on (a new one is shrunk
    keeping its signature). `progress(programs, shrinking)` after each program, and
    after each run tried in shrinking a finding (`shrinking` True). It ends early,
    with what it found, when halted, past its deadline, or on KeyboardInterrupt (Ctrl-C
    reaches a terminal's every process)."""
    searched = Searched(task.index, statistics=Statistics() if task.statistics else None)
    channel = Channel(task.channel) if task.channel is not None else None
    judging = judge_apart if task.apart else judge
    told = time.monotonic()
    telling = False  # that it is shrinking, as the channel last heard
    target: str | None = None  # the signature being shrunk
    shrinks = 0  # runs tried since the first disagreement

    def stopped() -> bool:
        return channel is not None and channel.halted_from() <= task.index

    def tell(shrinking: bool) -> None:
        nonlocal told, telling
        if progress is not None:
            progress(searched.programs, shrinking)
        if channel is not None and (shrinking != telling
                                    or time.monotonic() - told >= TOLD_EVERY):
            told, telling = time.monotonic(), shrinking
            channel.tell(task.index, searched.programs, shrinking)

    def disagrees(case: Run) -> bool:
        nonlocal target, shrinks
        if stopped():
            raise _Enough
        if target is None:
            if task.deadline is not None and time.time() >= task.deadline:
                raise _Enough
            searched.programs += 1
            tell(False)
        elif shrinks >= SHRINK_ATTEMPTS:
            raise _Enough  # small enough: keep the smallest so far
        else:
            shrinks += 1
            tell(True)
        verdict = judging(case, task.engines, task.budget)
        if target is None and searched.statistics is not None:
            searched.statistics.add(case, verdict)
        if not verdict.problems:
            return False
        found = signature(verdict)
        if target is None:
            searched.counts[found] = searched.counts.get(found, 0) + 1
            if task.keep_going and found in searched.findings:
                return False
            target = found
        elif task.keep_going and found != target:
            return False
        searched.findings[target] = Finding(case, verdict)  # the smallest so far
        return True

    # Losses after an instruction count compare only between engines given one file.
    levels = [engine.level for engine in task.engines if engine.level is not None]
    comparable = len(set(levels)) < len(levels)
    seeds = Random(task.seed)
    try:
        with contextlib.suppress(_Enough):
            for case in task.corpus:  # shrunk by deleting lines alone
                target = None
                if (task.keep_going or not searched.findings) and disagrees(case) \
                        and not stopped():
                    _delete_lines(searched, next(reversed(searched.findings)), task,
                                  stopped, tell)
            size = task.size + len(task.corpus)
            while searched.programs < size and (task.keep_going or not searched.findings):
                before = searched.programs
                target, shrinks = None, 0
                limits = settings(max_examples=size - searched.programs, database=None,
                                  deadline=None, suppress_health_check=list(HealthCheck),
                                  phases=(Phase.generate, Phase.shrink))
                with contextlib.suppress(NoSuchExample), contextlib.suppress(_Enough), \
                        only_hypothesis_constants():
                    find(runs(instruction_losses=comparable), disagrees, settings=limits,
                         random=Random(seeds.getrandbits(64)))
                if target is not None and not stopped():
                    _delete_lines(searched, target, task, stopped, tell)
                if searched.programs == before:  # Hypothesis generated nothing more
                    break
    except KeyboardInterrupt:  # in a worker: the campaign halts it too
        pass
    if channel is not None:
        channel.tell(task.index, searched.programs)
    gc.collect()  # a finished search is cyclic garbage: collect it now
    return searched


CORPUS_SUFFIX = ".rob"  # the programs of a corpus folder
SCRIPT_SUFFIXES = (".sensors.json", ".sensors.toml")  # a program's script beside it


def read_corpus(paths: Iterable[str]) -> tuple[list[Run], list[str]]:
    """The runs of `--corpus`: each RL/I file named, and each under a folder named (in
    the order of their paths), with the sensor script beside it (`NAME.sensors.json` or
    `.sensors.toml`: the examples, bench/corpus and a reproducer's `program.rob` are so
    laid out), or none; and a warning for each file left out, saying why (it cannot be
    read, the checker finds errors in it, its script is no valid script)."""
    runs: list[Run] = []
    warnings: list[str] = []
    for path in paths:
        files = [path] if not os.path.isdir(path) else sorted(
            os.path.join(folder, name) for folder, _, names in os.walk(path)
            for name in names if name.endswith(CORPUS_SUFFIX))
        for file in files:
            try:
                run = _corpus_run(file)
            except (SourceError, ScriptError, ReproducerError) as error:
                warnings.append(f"{error}; left out of the corpus")
                continue
            runs.append(run)
    return runs, warnings


def _corpus_run(file: str) -> Run:
    source = read_source(file).text
    if analyze(source).has_errors:
        raise ReproducerError(file, "the checker finds errors in it (rl1c check says which)")
    stem = file.removesuffix(CORPUS_SUFFIX)
    for script in (stem + suffix for suffix in SCRIPT_SUFFIXES):
        if os.path.exists(script):
            data = read_bounded(script, MAX_SCRIPT_BYTES, "a sensor script")
            try:
                document, _ = read_document(data, script, "toml" if script.endswith(
                    ".toml") else "json")
            except ConfigError as error:
                raise ScriptError(str(error)) from None
            parse_script(document, script)
            return Run(source, document)
    return Run(source, {})


def _delete_lines(searched: Searched, target: str, task: Search,
                  stopped: Callable[[], bool], tell: Callable[[bool], None]) -> None:
    """The finding of `target` reduced further by `_reduced` (no further once
    `stopped()`), `tell(True)` before each run tried."""
    judging = judge_apart if task.apart else judge

    def keeps(case: Run) -> bool:
        if stopped():
            return False
        tell(True)
        verdict = judging(case, task.engines, task.budget)
        return bool(verdict.problems) and (not task.keep_going
                                           or signature(verdict) == target)

    smallest = _reduced(searched.findings[target].case, keeps)
    searched.findings[target] = Finding(smallest, judging(smallest, task.engines,
                                                          task.budget))


def searches(seed: int, count: int | None) -> Iterator[tuple[int, int]]:
    """The seeds and sizes of a campaign's searches: BATCH programs each (the last what
    is left of `count`), each seeded by the next 64 bits of a generator seeded by
    `seed`. Endless without a count."""
    draws = Random(seed)
    planned = 0
    while count is None or planned < count:
        size = BATCH if count is None else min(BATCH, count - planned)
        planned += size
        yield draws.getrandbits(64), size


def campaign(engines: Sequence[Engine], budget: int, *, count: int | None,
             seconds: float | None, seed: int, progress: Callable[[int, float, int], None],
             executor: Executor | None = None, jobs: int = 1, keep_going: bool = False,
             found: Callable[[Finding], None] | None = None,
             channel: Channel | None = None, corpus: Sequence[Run] = (),
             statistics: bool = False, lost: tuple[type[BaseException], ...] = ()
             ) -> Outcome:
    """Run the `corpus`, then generated programs, on `engines` until `count` generated
    programs or `seconds` have passed, or until they disagree (with `keep_going`, until
    then whatever they find); `progress(programs, elapsed, shrinking)` as programs run
    and findings are shrunk (`shrinking`: the searches shrinking one now),
    `found(finding)` on each new signature's smallest run. The searches run in this
    process, or `jobs` at a time on `executor` (a search lost with its worker, an error
    of `lost`, runs again; SearchLost when it is lost each time); a disagreement stops
    the searches after the one that found it, and is the one of the first search in
    order that finds one, as in one process. `channel.halt()`
    (from a signal handler) stops every search, keeping their counts and findings. With
    `statistics`, the Outcome says what the programs did."""
    start = time.monotonic()
    deadline = None if seconds is None else time.time() + seconds
    if statistics:
        engines = [replace(engine, counting=True) if isinstance(engine, VmEngine) else engine
                   for engine in engines]
    own_channel = channel is None
    channel = Channel() if channel is None else channel
    results: dict[int, Searched] = {}
    stop_at = math.inf  # the first search that found something, without keep_going
    chunks = [tuple(corpus[start:start + BATCH]) for start in range(0, len(corpus), BATCH)]
    plan = itertools.chain(((0, 0, chunk) for chunk in chunks),
                           ((seed, size, ()) for seed, size in searches(seed, count)))
    index = 0

    def next_search() -> Search | None:
        nonlocal index
        if index >= stop_at or channel.halted_from() <= index or (
                deadline is not None and time.time() >= deadline):
            return None
        drawn = next(plan, None)
        if drawn is None:
            return None
        index += 1
        search_seed, size, runs_given = drawn
        return Search(index - 1, search_seed, size, tuple(engines), budget, keep_going,
                      deadline, channel.folder, runs_given, statistics)

    seen: set[str] = set()  # the signatures found so far
    untold = 0  # the first search whose findings are not yet told

    def tell(searched: Searched) -> None:
        for name in list(searched.findings):
            if name not in seen:
                seen.add(name)
                if found is not None:
                    found(searched.findings[name])
            elif keep_going:  # an earlier search's is kept: only counts are of this one
                del searched.findings[name]

    def keep(searched: Searched) -> None:
        nonlocal stop_at, untold
        results[searched.index] = searched
        if searched.findings and not keep_going and searched.index < stop_at:
            stop_at = searched.index
            channel.halt(searched.index + 1)
        # A signature's finding is the first search's in order that has one, whatever
        # order the searches end in: told once every search before it has ended.
        while untold in results:
            tell(results[untold])
            untold += 1

    def done() -> int:
        return sum(searched.programs for searched in results.values())

    try:
        if executor is None:
            before = 0  # the programs of the searches before this one

            def told(programs: int, shrinking: bool) -> None:
                progress(before + programs, time.monotonic() - start, int(shrinking))

            while (task := next_search()) is not None:
                before = done()
                keep(search(task, told))
        else:
            _on_executor(executor, jobs, next_search, keep, channel,
                         lambda programs, shrinking: progress(
                             done() + programs, time.monotonic() - start, shrinking), lost)
    finally:
        if own_channel:
            channel.close()
    counts: dict[str, int] = {}
    findings: dict[str, Finding] = {}
    gathered = Statistics() if statistics else None
    for searched in sorted(results.values(), key=lambda searched: searched.index):
        if gathered is not None and searched.statistics is not None:
            gathered.merge(searched.statistics)
        for name, number in searched.counts.items():
            counts[name] = counts.get(name, 0) + number
        for name, finding in searched.findings.items():
            findings.setdefault(name, finding)
    first = next(iter(findings.values()), None)
    return Outcome(done(), time.monotonic() - start, first, counts, findings,
                   channel.everything, gathered)


POLL = 0.5  # seconds between looks at the searches under way, for progress
LOSSES = 2  # times a search lost with its worker runs again


class SearchLost(Exception):
    """A search lost with its worker each of the LOSSES + 1 times it ran, the last ones
    with each program judged in a process of its own: what ends its workers is no
    program (something kills them, or the memory runs out). Raised from the last loss's
    error (a local pool's BrokenExecutor, a cluster's KilledWorker)."""


def _on_executor(executor: Executor, jobs: int, next_search: Callable[[], Search | None],
                 keep: Callable[[Searched], None], channel: Channel,
                 progress: Callable[[int, int], None], lost: tuple[type[BaseException], ...]
                 ) -> None:
    """Run the searches `next_search` gives on `executor`, `jobs` at a time, keeping
    each as it ends; one lost with its worker (an error of `lost`) runs again, up to
    LOSSES times (then SearchLost), each of its programs (and each tried in shrinking)
    then judged in a process of its own: its worker may have died of one of them, or
    beside the search that had it; either way the same programs, and one that ends its
    process is a finding."""
    pending: dict[Future[Searched], Search] = {}
    losses: dict[int, int] = {}

    def submit() -> None:
        while len(pending) < jobs and (task := next_search()) is not None:
            pending[executor.submit(search, task)] = task

    submit()
    while pending:
        finished, _ = wait(pending, timeout=POLL, return_when=FIRST_COMPLETED)
        for future in finished:
            task = pending.pop(future)
            error = future.exception()
            if isinstance(error, lost):
                if losses.get(task.index, 0) >= LOSSES:
                    raise SearchLost(f"search {task.index} lost {LOSSES + 1} times"
                                     ) from error
                losses[task.index] = losses.get(task.index, 0) + 1
                task = replace(task, apart=True)
                pending[executor.submit(search, task)] = task
                continue
            keep(future.result())
        submit()
        progress(*channel.told(task.index for task in pending.values()))


def _reduced(case: Run, disagrees: Callable[[Run], bool]) -> Run:
    """The run reduced by compiler/reduce.py's passes while it disagrees, in at most
    REDUCE_TESTS runs: lines, statements and terms deleted, operands and the sensor
    script's numbers made smaller, its readings and losses deleted, then the formatter's
    layout; the last step of shrinking, cheap where Hypothesis' is slow (a slow `exec:`
    engine)."""
    def still(candidate: Case) -> bool:
        return disagrees(Run(candidate.source, json.loads(candidate.script or "{}")))

    try:
        reduced = reduce(Case(case.source, script_text(case.script)), still,
                         max_tests=REDUCE_TESTS).case
    except NotInteresting:  # judged again, it agrees: an engine that varies
        return case
    return Run(reduced.source, json.loads(reduced.script or "{}"))


FINDING_FOLDER = "finding-"  # each finding's folder under --out: finding-1, finding-2...


@dataclass(frozen=True)
class Reproducer:
    folder: str  # the finding's own folder
    replay: str  # the command that replays it


def write_reproducer(out: str, finding: Finding, engines: Sequence[Engine],
                     budget: int) -> Reproducer:
    """Write the run, its compiled files, each engine's run (of those that ran, when one
    ended its process), the engines and budget (`engines.json`) and `replay.sh` (which
    judges the run again in a process of its own, and names each engine's command) into
    a new folder under `out` (made for it, so that nothing there is replaced, followed or
    written into: the first free `finding-N`); OSError when that cannot be done."""
    os.makedirs(out, exist_ok=True)
    folder = _new_folder(out)
    case = finding.case

    def write(name: str, data: bytes | str) -> str:
        write_atomically(os.path.join(folder, name),
                         data.encode("utf-8") if isinstance(data, str) else data)
        return name

    write(SOURCE, case.source)
    write(SCRIPT, json.dumps(case.script, indent=2) + "\n")
    write(ENGINES, json.dumps({"engines": [engine.name for engine in engines],
                               "budget": budget}, indent=2) + "\n")
    commands = ["#!/bin/sh",
                "# Runs every engine on the program again, in a process of its own, and",
                "# prints what still differs: exit status 1 while the engines disagree or",
                "# one ends its process, 0 once they agree. Run it from the folder the",
                "# campaign ran in when an exec: engine names relative paths.",
                "#", "# Each engine alone (the files named are in this folder):"]
    for index, engine in enumerate(engines, 1):
        slug = re.sub(r"[^A-Za-z0-9]+", "-", engine.name).strip("-")[:40]
        observation = finding.verdict.observations.get(engine.name)
        if observation is not None:  # none for those after one that ended its process
            write(f"run-{index}-{slug}.json",
                  json.dumps(observation.document, indent=2) + "\n")
        commands.append("#   " + _replay(engine, case, budget, write))
    commands.append('exec rl1c fuzz --replay "$(dirname "$0")"')
    write("replay.sh", "\n".join(commands) + "\n")
    return Reproducer(folder, f"sh {shlex.quote(os.path.join(folder, 'replay.sh'))}")


class ReproducerError(Exception):
    """A reproducer's file that is not as `write_reproducer` writes it: its `path`, and
    what is wrong with it (`detail`)."""

    def __init__(self, path: str, detail: str) -> None:
        super().__init__(f"{path}: {detail}")
        self.path = path
        self.detail = detail


@dataclass(frozen=True)
class Replay:
    """A reproducer read back: the run, and the engines and budget that judged it."""

    case: Run
    engines: list[Engine]
    budget: int


def read_reproducer(folder: str) -> Replay:
    """The reproducer `write_reproducer` wrote into `folder`, as it now is (the program
    and script may have been edited); files.SourceError when a file cannot be read,
    ReproducerError when one is not what it should be."""
    path = os.path.join(folder, SOURCE)
    source = read_source(path).text
    if analyze(source).has_errors:
        raise ReproducerError(path, "the checker finds errors in it (rl1c check says "
                              "which); the engines compare only programs it accepts")
    path = os.path.join(folder, SCRIPT)
    script = _json(path, read_bounded(path, MAX_SCRIPT_BYTES, "a sensor script"))
    try:
        parse_script(script, path)
    except ScriptError as error:
        raise ReproducerError(path, str(error)) from None
    path = os.path.join(folder, ENGINES)
    match _json(path, read_bounded(path, MAX_ENGINES_BYTES, "a list of engines")):
        case {"engines": [*names], "budget": int(budget)} if 1 <= budget <= MAX_BUDGET:
            pass
        case _:
            raise ReproducerError(path, 'expected {"engines": [NAME, ...], "budget": N} '
                                  f"with N from 1 to {MAX_BUDGET}")
    engines = [engine_named(name) if isinstance(name, str) else None for name in names]
    unknown = [repr(name) for name, engine in zip(names, engines, strict=True)
               if engine is None]
    if unknown or len(engines) < 2:
        raise ReproducerError(path, f"unknown engine {unknown[0]}" if unknown
                              else "it names fewer than two engines")
    return Replay(Run(source, script), [engine for engine in engines if engine], budget)


def _json(path: str, data: bytes) -> Any:
    try:
        return json.loads(data)
    except (ValueError, RecursionError) as error:  # not UTF-8, not JSON, nested too deeply
        raise ReproducerError(path, f"it is not JSON ({error})") from None


def _new_folder(out: str) -> str:
    """The first `finding-N` under `out` that did not exist, made now (by this process
    alone, even when campaigns write to `out` together)."""
    number = 1
    while True:
        folder = os.path.join(out, f"{FINDING_FOLDER}{number}")
        try:
            os.mkdir(folder)
            return folder
        except FileExistsError:
            number += 1


def _replay(engine: Engine, case: Run, budget: int,
            write: Callable[[str, bytes | str], str]) -> str:
    run = f"--sensors {SCRIPT} --budget {budget} --format json"
    if isinstance(engine, AstEngine):
        return f"rl1c run {SOURCE} --engine ast {run}"
    if isinstance(engine, VmEngine | CEngine):
        ilc = write(f"program-O{engine.level}.ilc", compiled(case.source, engine.level))
        return f"rl1c run {ilc} {run}" + (" --engine c" if isinstance(engine, CEngine) else "")
    if isinstance(engine, ExecEngine):
        ilc = write(f"program-O{engine.level}.ilc", compiled(case.source, engine.level))
        return engine.command_line(ilc, SCRIPT, budget)
    if isinstance(engine, BatchEngine):
        job = write(f"job-O{engine.level}.json", engine.job(case, budget) + b"\n")
        return f"{engine.command} < {job}"
    return f"# {engine.name}: no command replays it"
