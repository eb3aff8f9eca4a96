"""`rl1c fuzz`: differential fuzzing of RL/I engines, ours and anyone's.

The campaign and the comparison are compiler/fuzz.py's and compiler/differential.py's;
this module reads the options, draws the progress bar and reports. It imports them
when it runs: they load Hypothesis.
"""

from __future__ import annotations

import json
import os
import random
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import partial
from types import FrameType
from typing import TYPE_CHECKING, Any, TextIO

import click

from rl1.compiler.reporting.render import EXIT_ERRORS

from .command import (
    EXIT_INTERNAL,
    PATH,
    Command,
    CommandError,
    a_budget,
    at_least_one,
    choice_option,
    message_line,
    or_none,
    stop_signals_handled,
)

if TYPE_CHECKING:
    from rl1.compiler.differential import Engine
    from rl1.compiler.fuzz import Channel, Finding, Outcome, Reproducer

SECTION = "Testing"
COMMAND_PATH = "rl1c fuzz"  # what its warnings begin with

DEFAULT_COUNT = 1000
DEFAULT_BUDGET = 20_000  # generated programs are short; a runaway is found quickly
BAR_WIDTH = 30
REDRAW_EVERY = 0.2  # seconds between redraws of the bar on a terminal
PROGRESS_EVERY = 10.0  # seconds between progress lines elsewhere


@contextmanager
def needing_hypothesis(purpose: str, otherwise: str) -> Iterator[None]:
    """Imports that need Hypothesis, the optional part `fuzz` of rl1 (rl1c fuzz's, and
    rl1c reduce --engine's): without it, a usage error saying that `purpose` needs it
    and how to install it, or `otherwise`."""
    try:
        yield
    except ModuleNotFoundError as error:
        if (error.name or "").partition(".")[0] != "hypothesis":
            raise
        raise CommandError(f"{purpose} with Hypothesis, an optional part of rl1 that is "
                           f"not installed here; install it with `pip install 'rl1[fuzz]'`"
                           f"{otherwise}") from None


@click.command(cls=Command)
@click.option("--engine", "engine_names", multiple=True, metavar="NAME",
              help="an engine to compare, repeatable: ast, vm-O0, vm-O1, vm-O2, the C VM "
                   "of the firmware c-O0, c-O1, c-O2 (built on first use), or "
                   "exec:COMMAND ({ilc}, {sensors} and {budget} replaced; it prints the run "
                   "as `rl1c run --format json` does), given the file compiled with -O0, "
                   "or exec-O1:COMMAND, exec-O2:COMMAND at that level; exec-batch:COMMAND "
                   "(and -O1, -O2) started once, reading a job a line and answering each "
                   "(spec/optimization.md, section 5; `rl1c run --batch` is one). Default: "
                   "ast, vm-O0, vm-O1, vm-O2; the first is the reference")
@click.option("--count", type=str, default=None, callback=or_none(at_least_one),
              metavar="N",
              help=f"programs to generate and run, after any --corpus (default "
                   f"{DEFAULT_COUNT})")
@click.option("--time", "seconds", type=str, default=None, metavar="SECONDS",
              callback=or_none(at_least_one),
              help="run for this long instead of a count")
@click.option("--seed", type=str, default=None, metavar="N",
              help="the seed of the generator, to repeat a campaign (default: random)")
@click.option("--out", "out_dir", default="fuzz-out", show_default=True, metavar="DIR",
              type=PATH, help="the folder under which a disagreement's reproducer is written, in a "
                   "new folder finding-N of its own")
@click.option("--budget", type=str, default=str(DEFAULT_BUDGET), callback=a_budget,
              metavar="N", show_default=True, help="the budget of every run")
@click.option("--jobs", type=str, default=None, metavar="J",
              callback=or_none(at_least_one),
              help="processes that run the searches (default: one per core); the "
                   "programs are the same for any J")
@click.option("--scheduler", metavar="ADDRESS",
              help="run the searches on the Dask cluster of this scheduler "
                   "(tcp://HOST:8786; the extra rl1[cluster] here, rl1[fuzz] on its "
                   "workers) instead of local processes; the same programs")
@click.option("--corpus", "corpus_paths", multiple=True, metavar="PATH", type=PATH,
              help="programs to run first, repeatable: an RL/I file, or a folder of them "
                   "(such as examples/, bench/corpus or --out's findings), each with the "
                   "sensor script NAME.sensors.json or .toml beside it if there is one")
@click.option("--keep-going", is_flag=True,
              help="go on past disagreements: each kind (its signature: the engines, "
                   "the difference and the first differing call, spec/optimization.md) "
                   "gets a reproducer of its own, and the summary counts the programs "
                   "of each")
@choice_option("--format", "fuzz_format", choices=("text", "json"), default="text",
               help="text: the summary for people; json: the summary on standard error, "
                    "and on standard output one object with what the programs did "
                    "(endings, handler jumps, opcodes executed, optimizer passes that "
                    "fired, findings; spec/optimization.md, section 5)")
@click.option("--replay", "replay_dir", default=None, metavar="DIR", type=PATH,
              help="judge a reproducer again (a finding-N folder, as its replay.sh does) "
                   "with its engines and budget: exit status 1 while they disagree")
def fuzz(engine_names: tuple[str, ...], count: int | None, seconds: int | None,
         seed: str | None, out_dir: str, budget: int, jobs: int | None,
         scheduler: str | None, corpus_paths: tuple[str, ...], keep_going: bool,
         fuzz_format: str, replay_dir: str | None) -> int:
    """Run generated programs on several engines and compare what they do.

    Every program (with a sensor script to match) runs on each engine; the runs must
    agree on the device trace, how they end and the final variables, and optimized code
    must keep the budget invariant (spec/optimization.md). The programs come in searches
    of 100, run --jobs at a time, each seeded from --seed (so a seed gives the same
    programs on any number of processes). On the first disagreement the program is
    shrunk to a small one, written with each engine's run and a replay script to --out,
    and the difference printed; --replay judges it again. Ctrl-C or SIGTERM stops the
    campaign with its summary and its seed. A program on which an engine ends its
    process (the C VM's crash) is a finding too, shrunk as any. Exit status: 0
    all agreed, 1 a disagreement or such a program, 2 a usage problem, 130 or 143
    stopped by Ctrl-C or SIGTERM."""
    with needing_hypothesis("rl1c fuzz generates programs", " (or `pip install hypothesis`)"):
        from rl1.compiler.differential import (
            DEFAULT_ENGINES,
            ENGINE_NAMES,
            EngineUnavailable,
            engine_named,
        )
        from rl1.compiler.fuzz import (
            LOSSES,
            Channel,
            SearchLost,
            campaign,
            read_corpus,
            write_reproducer,
        )
    from rl1.compiler.executors import ClusterLost, Unavailable, workers
    from rl1.vm.native import BuildError

    from .sim_campaign import MAX_JOBS, no_workers_left

    if replay_dir is not None:
        if engine_names or count is not None or seconds is not None or seed is not None \
                or corpus_paths:
            raise click.UsageError("--replay takes the engines and budget of the "
                                   "reproducer: give it without --engine, --count, --time, "
                                   "--seed and --corpus")
        return _replay(replay_dir)
    if count is not None and seconds is not None:
        raise click.UsageError("give --count or --time, not both")
    problem = _unwritable(out_dir)
    if problem is not None:  # found now, not after a campaign that found something
        raise click.UsageError(f"argument --out: {out_dir}: {problem}")
    engines: list[Engine] = []
    for name in engine_names or DEFAULT_ENGINES:
        engine = engine_named(name)
        if engine is None:
            raise click.UsageError(f"argument --engine: unknown engine {name!r} (choose from "
                                   f"{', '.join(ENGINE_NAMES)}, or exec:COMMAND, "
                                   "exec-O1:COMMAND, exec-O2:COMMAND, the same with "
                                   "exec-batch)")
        engines.append(engine)
    if len({engine.name for engine in engines}) < 2 or len(set(engine_names)) < len(
            engine_names):
        raise click.UsageError("argument --engine: give at least two different engines")
    try:
        seed_value = random.SystemRandom().randrange(2**32) if seed is None else int(seed)
    except ValueError:
        raise click.UsageError(f"argument --seed: expected a whole number, got {seed!r}"
                               ) from None
    if jobs is not None and scheduler is not None:
        raise click.UsageError("--jobs counts local processes, and --scheduler gives the "
                               "searches to a cluster's workers: give one of them")
    if jobs is not None and jobs > MAX_JOBS:
        raise click.UsageError(f"argument --jobs: at most {MAX_JOBS} processes on one "
                               "machine")
    missing = [path for path in corpus_paths if not os.path.exists(path)]
    if missing:
        raise click.UsageError(f"argument --corpus: {missing[0]}: no such file or folder")
    corpus, warnings = read_corpus(corpus_paths)
    for warning in warnings:
        print(message_line(COMMAND_PATH, "warning", warning), file=sys.stderr)
    limit = None if seconds is not None else count or DEFAULT_COUNT
    bar = _Bar(limit, seconds)
    channel = Channel()
    written: dict[str, Reproducer | OSError] = {}  # --keep-going: each signature's

    def write(finding: Finding) -> None:  # as each is found, kept if the campaign stops
        try:
            written[finding.signature] = write_reproducer(out_dir, finding, engines, budget)
        except OSError as error:
            written[finding.signature] = error

    try:
        # Processes even for one job, and on a cluster a process a search: an engine
        # that ends the process it runs in (the C VM's crash) ends that one, whose
        # searches run again to name the program; a local pool is made again, and a
        # cluster's worker lives on. Each time, the campaign says so.
        with _halted_by_signals(channel) as signalled, \
                workers(jobs or os.cpu_count() or 1, scheduler,
                        lost=lambda: bar.warn(WORKER_LOST), isolated=True,
                        unmanned=lambda: bar.warn(no_workers_left(scheduler or "", "the searches"))
                        ) as held:
            outcome = campaign(engines, budget, count=limit, seconds=seconds,
                               seed=seed_value, progress=bar.update, executor=held.executor,
                               jobs=max(held.slots, 1), keep_going=keep_going,
                               found=write if keep_going else None, channel=channel,
                               corpus=corpus, statistics=fuzz_format == "json",
                               lost=held.lost)
    # Such as no C compiler for c-ON, or a cluster that cannot be had or was lost.
    except (BuildError, EngineUnavailable, Unavailable, ClusterLost) as error:
        raise CommandError(str(error)) from None
    except SearchLost:  # though no program ended its process
        raise CommandError(f"a worker process ended abruptly {LOSSES + 1} times running "
                           "one search, though none of its programs ended the process that ran "
                           "it (something killed the workers, or the memory ran out); the "
                           f"campaign runs again with --seed {seed_value}", EXIT_INTERNAL
                           ) from None
    finally:
        bar.close()
        channel.close()
    names = ", ".join(engine.name for engine in engines)
    rate = outcome.programs / outcome.seconds if outcome.seconds else 0.0
    of_corpus = f" (the corpus of {len(corpus)} first)" if corpus else ""
    summary = (f"fuzz: {outcome.programs} programs{of_corpus} in {outcome.seconds:.1f} s "
               f"({rate:.1f} per second); engines {names}; seed {seed_value}")
    stopped = 128 + signalled[0] if signalled else 0
    if stopped:
        summary += ", stopped by a signal before its end"
    say = partial(click.echo, err=fuzz_format == "json")  # JSON alone on standard output
    unwritten: OSError | None = None
    if outcome.finding is None:
        say(f"{summary}: " + ("all agreed so far" if stopped else "all agreed"))
    elif keep_going:
        _report_groups(summary, outcome, written, engines[0].name, out_dir, say)
    else:
        finding = outcome.finding
        say(f"{summary}: {_found(finding, engines[0].name)}:\n"
            f"{_numbered(finding.case.source)}\n\n" + "\n".join(finding.verdict.problems))
        write(finding)
        match written[finding.signature]:
            case OSError() as unwritten:
                pass
            case reproducer:
                say(f"\nreproducer: {reproducer.folder} (program, sensor script, each "
                    f"engine's run); replay: {reproducer.replay}"
                    + ("\n  = help: replay.sh names each engine's own command, to run the "
                       "one that ends its process under a debugger"
                       if finding.verdict.ended is not None else ""))
    if fuzz_format == "json":
        click.echo(json.dumps(_statistics(outcome, seed_value, engines, budget, len(corpus),
                                          written), indent=2))
    if unwritten is not None:  # such as a full disk: the finding is printed above
        raise CommandError(f"cannot write the reproducer under {out_dir} "
                           f"({unwritten.strerror or unwritten}); the program is above, and the "
                           "campaign runs again with the same --seed", EXIT_ERRORS)
    return stopped or (EXIT_ERRORS if outcome.finding is not None else 0)


WORKER_LOST = ("a worker process ended abruptly (killed, out of memory, or ended by an "
               "engine); its searches run again, each program in a process of its own, "
               "to find the program that ended it")


def _found(finding: Finding, reference: str) -> str:
    """What a campaign found, before its program."""
    if finding.verdict.ended is not None:
        return "an engine ends the process it runs in\n\nthe smallest program found that does it"
    return f"the engines disagree (reference: {reference})\n\nthe smallest program found"


def _statistics(outcome: Outcome, seed: int, engines: list[Engine], budget: int,
                corpus: int, written: dict[str, Reproducer | OSError]) -> dict[str, Any]:
    """`--format json`: the campaign as one object (spec/optimization.md, section 5)."""
    from rl1.compiler.fuzz import Reproducer

    assert outcome.statistics is not None
    findings = [{"signature": name, "programs": programs,
                 "reproducer": reproducer.folder if isinstance(
                     reproducer := written.get(name), Reproducer) else None}
                for name, programs in sorted(outcome.counts.items(),
                                             key=lambda item: (-item[1], item[0]))]
    return {"programs": outcome.programs, "corpus": corpus,
            "seconds": round(outcome.seconds, 3), "seed": seed,
            "engines": [engine.name for engine in engines], "budget": budget,
            "stopped": outcome.stopped, **outcome.statistics.to_json(),
            "findings": findings}


def _report_groups(summary: str, outcome: Outcome, written: dict[str, Reproducer | OSError],
                   reference: str, out_dir: str, say: Callable[[str], None]) -> None:
    """--keep-going's summary: each signature, the most frequent first, with the programs
    that showed it and its reproducer."""
    from rl1.compiler.fuzz import Reproducer

    groups = sorted(outcome.counts.items(), key=lambda item: (-item[1], item[0]))
    lines = [f"{summary}: {len(groups)} kind{'s' if len(groups) != 1 else ''} of "
             f"disagreement (reference: {reference}), by the programs that showed each:"]
    for name, programs in groups:
        lines.append(f"{programs:>7}  {name}")
        match written.get(name):
            case Reproducer(folder=folder, replay=replay):
                lines.append(f"         reproducer: {folder}; replay: {replay}")
            case OSError() as error:
                lines.append(f"         reproducer: not written under {out_dir} "
                             f"({error.strerror or error}); the campaign finds it again "
                             "with the same --seed")
    say("\n".join(lines))


@contextmanager
def _halted_by_signals(channel: Channel) -> Iterator[list[int]]:
    """While in effect, SIGINT and SIGTERM halt the campaign's searches (which end
    within a program, keeping what they found) instead of stopping rl1c; the signals
    caught are in the list it gives."""
    caught: list[int] = []

    def halt(signum: int, frame: FrameType | None) -> None:
        caught.append(signum)
        channel.halt()

    with stop_signals_handled(halt):
        yield caught


def _numbered(source: str) -> str:
    from rl1.compiler.frontend.source import split_lines

    return "\n".join(f"{number:4} | {line}" for number, line
                     in enumerate(split_lines(source), 1))


def _replay(folder: str) -> int:
    """Judge the reproducer in `folder` again, in a process of its own: 1 while its
    engines disagree or one ends its process."""
    from rl1.compiler.differential import EngineUnavailable, judge_apart
    from rl1.compiler.files import SourceError
    from rl1.compiler.fuzz import ReproducerError, read_reproducer
    from rl1.vm.native import BuildError

    from .streams import invalid_file, read_failure

    try:
        replay = read_reproducer(folder)
    except SourceError as error:
        raise read_failure(error, "reproducer's file") from None
    except ReproducerError as error:
        raise invalid_file("reproducer's file", error.path, error.detail,
                           "write it as `rl1c fuzz` did, or replay another finding"
                           ) from None
    try:
        verdict = judge_apart(replay.case, replay.engines, replay.budget)
    except (BuildError, EngineUnavailable) as error:
        raise CommandError(str(error)) from None
    names = ", ".join(engine.name for engine in replay.engines)
    program = _numbered(replay.case.source)
    if not verdict.problems:
        click.echo(f"replay: the engines agree now (engines {names}; budget "
                   f"{replay.budget}) on:\n{program}")
        return 0
    still = (f"an engine still ends the process it runs in (budget {replay.budget})"
             if verdict.ended is not None else "the engines still disagree (reference: "
             f"{replay.engines[0].name}; budget {replay.budget})")
    click.echo(f"replay: {still} on:\n{program}\n\n" + "\n".join(verdict.problems))
    return EXIT_ERRORS


def _unwritable(folder: str) -> str | None:
    """Why the reproducer of a finding could not be written under `folder` (which need
    not exist yet), or None."""
    path = os.path.abspath(folder)
    while not os.path.lexists(path):
        path = os.path.dirname(path)
    if not os.path.isdir(path):  # a file, or a link to nothing
        return "it is not a folder" if path == os.path.abspath(folder) \
            else f"{path} is not a folder"
    if not os.access(path, os.W_OK | os.X_OK):
        return f"{path} cannot be written to; name a folder of yours"
    return None


class _Bar:
    """Progress on standard error: on a terminal a bar redrawn in place every
    REDRAW_EVERY seconds; elsewhere (CI, a log file) a plain line every PROGRESS_EVERY
    seconds, which a log keeps readable. Each says how many findings are being shrunk,
    which can take a while after the last program has run."""

    def __init__(self, count: int | None, seconds: int | None, stream: TextIO | None = None
                 ) -> None:
        self.count, self.seconds = count, seconds
        self.stream = stream or sys.stderr
        self.terminal = self.stream.isatty()
        self.shown = 0.0  # the elapsed time of the last line

    def update(self, programs: int, elapsed: float, shrinking: int = 0) -> None:
        if elapsed - self.shown < (REDRAW_EVERY if self.terminal else PROGRESS_EVERY):
            return
        self.shown = elapsed
        rate = programs / elapsed if elapsed else 0.0
        of_count = f" of {self.count}" if self.count else ""
        of_time = f" of {self.seconds}" if self.seconds else ""
        done = (f"{programs}{of_count} programs, {rate:.1f} per second, "
                f"{elapsed:.0f}{of_time} s")
        if shrinking:
            done += f"; shrinking {shrinking} finding{'s' if shrinking != 1 else ''}"
        if not self.terminal:
            self.stream.write(f"fuzz: {done}\n")
        else:
            part = programs / self.count if self.count else elapsed / (self.seconds or 1)
            filled = int(BAR_WIDTH * min(part, 1.0))
            # Erased past its end: a line shorter than the last (its rate a digit
            # shorter, the shrinking said no more) leaves nothing of that one.
            self.stream.write(f"\r[{'#' * filled}{'.' * (BAR_WIDTH - filled)}] {done}\033[K")
        self.stream.flush()

    def warn(self, warning: str) -> None:
        """Say `warning` on a line of its own (a bar is drawn again after it)."""
        erase = "\r\033[K" if self.terminal and self.shown else ""  # the bar drawn so far
        self.stream.write(erase + message_line(COMMAND_PATH, "warning", warning) + "\n")
        self.stream.flush()

    def close(self) -> None:
        if self.terminal and self.shown:
            self.stream.write("\n")


COMMANDS = (fuzz,)
