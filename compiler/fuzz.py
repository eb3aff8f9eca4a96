"""A differential fuzzing campaign: generated runs on several engines until one
disagrees, then that run shrunk to a small one and written down as a reproducer.

Runs come from `strategies.runs()`; Hypothesis' `find` generates them and, on the first
disagreement, shrinks the run to the smallest it can find that still disagrees (the
disagreement may change on the way: it is the smallest run that shows one), for at most
SHRINK_ATTEMPTS runs, a bound in runs rather than seconds, so that a seed gives the same
reproducer on a loaded machine as on an idle one. `judge` in differential.py decides
what disagrees (spec/optimization.md).
"""

from __future__ import annotations

import contextlib
import gc
import json
import os
import re
import shlex
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from random import Random
from typing import Any, TypeVar

from hypothesis import HealthCheck, Phase, find, settings
from hypothesis.errors import NoSuchExample

from rl1.compiler.analysis import analyze
from rl1.compiler.differential import (
    AstEngine,
    CEngine,
    Engine,
    ExecEngine,
    Verdict,
    VmEngine,
    compiled,
    engine_named,
    judge,
)
from rl1.compiler.files import read_bounded, write_atomically
from rl1.compiler.frontend.source import read_source, split_lines
from rl1.compiler.runner import MAX_SCRIPT_BYTES
from rl1.compiler.strategies import Run, runs
from rl1.vm.faults import MAX_BUDGET
from rl1.vm.sensor_script import ScriptError, parse_script

# Hypothesis' shrinking stops after trying so many runs, with the smallest so far (on a
# planted shift bug it went on for 1,100 to 1,700 runs to save a character or two, which
# deleting lines and statements then does in far fewer).
SHRINK_ATTEMPTS = 500
# Programs per Hypothesis search. Its runner keeps what it learnt of every run it
# generated (about 130 KB each) until the search ends, so a long campaign is many short
# searches, each seeded from --seed, with their garbage collected in between.
BATCH = 500
LABEL = re.compile(r"[ \t\f\v]*:[0-9]*")  # a label where a line starts (language 3.1)
SOURCE = "program.rob"
SCRIPT = "program.sensors.json"
ENGINES = "engines.json"  # the engines a reproducer names, and the budget
MAX_ENGINES_BYTES = 2**20


@dataclass(frozen=True)
class Finding:
    """The smallest run found that disagrees, and every engine's run of it."""

    case: Run
    verdict: Verdict


@dataclass(frozen=True)
class Outcome:
    programs: int  # programs run up to the first disagreement (or in all)
    seconds: float  # the time they took (shrinking not counted)
    finding: Finding | None


class _Enough(Exception):
    """The campaign's time is up, or shrinking has tried its runs."""


def campaign(engines: Sequence[Engine], budget: int, *, count: int | None,
             seconds: float | None, seed: int,
             progress: Callable[[int, float], None]) -> Outcome:
    """Run generated programs on `engines` until `count` programs or `seconds` have
    passed, or until they disagree; `progress(programs, elapsed)` after each program."""
    start = time.monotonic()
    programs = 0
    found_after: float | None = None  # seconds until the first disagreement
    smallest: Run | None = None  # the last run that disagreed: the smallest so far
    attempts = 0  # runs tried since the first disagreement

    def disagrees(case: Run) -> bool:
        nonlocal programs, found_after, smallest, attempts
        elapsed = time.monotonic() - start
        if found_after is None:
            if seconds is not None and elapsed >= seconds:
                raise _Enough
            programs += 1
            progress(programs, elapsed)
        elif attempts >= SHRINK_ATTEMPTS:
            raise _Enough  # small enough: keep the smallest so far
        else:
            attempts += 1
        if not judge(case, engines, budget).problems:
            return False
        if found_after is None:
            found_after = elapsed
        smallest = case
        return True

    # Losses after an instruction count compare only between engines given one file.
    levels = [engine.level for engine in engines if engine.level is not None]
    comparable = len(set(levels)) < len(levels)
    seeds = Random(seed)
    with contextlib.suppress(_Enough):
        while smallest is None and (count is None or programs < count):
            before = programs
            batch = BATCH if count is None else min(BATCH, count - programs)
            limits = settings(max_examples=batch, database=None, deadline=None,
                              suppress_health_check=list(HealthCheck),
                              phases=(Phase.generate, Phase.shrink))
            with contextlib.suppress(NoSuchExample):
                smallest = find(runs(instruction_losses=comparable), disagrees,
                                settings=limits,
                                random=Random(seeds.getrandbits(64)))
            if programs == before:  # Hypothesis generated nothing more: stop, not spin
                break
            gc.collect()  # a finished search is cyclic garbage: collect it now
    elapsed = time.monotonic() - start if found_after is None else found_after
    if smallest is None:
        return Outcome(programs, elapsed, None)
    smallest = _deleted(smallest, lambda case: bool(judge(case, engines, budget).problems))
    return Outcome(programs, elapsed, Finding(smallest, judge(smallest, engines, budget)))


def _deleted(case: Run, disagrees: Callable[[Run], bool]) -> Run:
    """The run with its comments gone and each label on a line of its own, then the
    lines, and the statements of each line, that the disagreement does not need (and
    the checker does not miss) deleted, in halves, quarters... down to one, until
    nothing more goes: the last step of shrinking, cheap where Hypothesis' is slow (a
    slow `exec:` engine)."""
    def source(lines: list[list[str]]) -> str:
        return "".join(";".join(statements) + "\n" for statements in lines)

    def keeps(lines: list[list[str]]) -> bool:
        text = source(lines)
        return not analyze(text).has_errors and disagrees(Run(text, case.script))

    lines: list[list[str]] = []
    for line in split_lines(case.source):
        label = LABEL.match(line)
        code = line.split("'", 1)[0][label.end() if label else 0:]
        lines += [[label.group().strip()]] if label else []
        lines += [code.split(";")] if code.strip(" \t\f\v;") else []
    if not keeps(lines):
        return case  # the checker objects to the program laid out so
    while True:
        before = len(source(lines))
        lines = _reduce(lines, keeps)
        for row in range(len(lines)):
            lines[row] = _reduce(lines[row], _in_row(lines, row, keeps))
        if len(source(lines)) == before:
            return Run(source(lines), case.script)


def _in_row(lines: list[list[str]], row: int, keeps: Callable[[list[list[str]]], bool]
            ) -> Callable[[list[str]], bool]:
    """`keeps` for the statements of one line, the others as they are."""
    return lambda statements: keeps([*lines[:row], statements, *lines[row + 1:]])


T = TypeVar("T")


def _reduce(items: list[T], keeps: Callable[[list[T]], bool]) -> list[T]:
    """`items` without the runs of them that `keeps` does not need, trying runs of half
    their number first, then of a quarter, down to single items; never empty."""
    size = len(items) // 2
    while size >= 1:
        start = 0
        while start < len(items):
            shorter = items[:start] + items[start + size:]
            if shorter and keeps(shorter):
                items = shorter
            else:
                start += size
        size //= 2
    return items


FINDING_FOLDER = "finding-"  # each finding's folder under --out: finding-1, finding-2...


@dataclass(frozen=True)
class Reproducer:
    folder: str  # the finding's own folder
    replay: str  # the command that replays it


def write_reproducer(out: str, finding: Finding, engines: Sequence[Engine],
                     budget: int) -> Reproducer:
    """Write the run, its compiled files, each engine's run, the engines and budget
    (`engines.json`) and `replay.sh` (which judges the run again, and names each engine's
    command) into a new folder under `out` (made for it, so that nothing there is
    replaced, followed or written into: the first free `finding-N`); OSError when that
    cannot be done."""
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
                "# Runs every engine on the program again and prints what still differs: exit",
                "# status 1 while the engines disagree, 0 once they agree. Run it from the",
                "# folder the campaign ran in when an exec: engine names relative paths.",
                "#", "# Each engine alone (the files named are in this folder):"]
    for index, engine in enumerate(engines, 1):
        slug = re.sub(r"[^A-Za-z0-9]+", "-", engine.name).strip("-")[:40]
        write(f"run-{index}-{slug}.json",
              json.dumps(finding.verdict.observations[engine.name].document, indent=2) + "\n")
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
    return f"# {engine.name}: no command replays it"
