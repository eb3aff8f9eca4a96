"""`rl1c reduce`: a program (and its sensor script) made as small as it can be while a
command still finds it interesting, in creduce's manner, or while engines still
disagree on it.

The passes are compiler/reduce.py's; this module reads the files, runs the command on
each candidate in a temporary folder, reports and writes the result.
"""

from __future__ import annotations

import contextlib
import json
import os
import shlex
import signal
import subprocess
import sys
import tempfile
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import click

from rl1.compiler.executors import orphans_ended
from rl1.compiler.files import SourceError, read_bounded, refuses_writing
from rl1.compiler.reporting.render import EXIT_ERRORS

from .command import (
    EXIT_INTERRUPTED,
    PATH,
    Command,
    CommandError,
    a_budget,
    at_least_one,
    or_none,
)
from .streams import (
    encode_like,
    invalid_config,
    invalid_file,
    read_failure,
    same_file,
    with_suffix,
    write_file,
)

if TYPE_CHECKING:
    from rl1.compiler.differential import Engine
    from rl1.compiler.frontend.source import Source
    from rl1.compiler.reduce import Case

SECTION = "Testing"
DEFAULT_MAX_TESTS = 2000
DEFAULT_TIMEOUT = 10  # seconds a test may take, as long as an exec: engine of rl1c fuzz
OUTPUT_KEPT = 4096  # the end of a test's output, for the message when the original fails
SCRIPT_ROLE = "sensor script"


@click.command(cls=Command)
@click.argument("file", metavar="FILE.rob", type=PATH)
@click.option("--sensors", "sensors", metavar="S", type=PATH, default=None,
              help="the sensor script that goes with the program (reduced too when JSON)")
@click.option("--interesting", "command", metavar="CMD", default=None,
              help="a shell command that exits 0 while a candidate is still interesting; it "
                   "runs in a new temporary folder holding the candidate program (and "
                   "script) under the same file names, so name what it runs by an "
                   "absolute path")
@click.option("--engine", "engine_names", multiple=True, metavar="NAME",
              help="instead of --interesting: engines as `rl1c fuzz --engine` names them, "
                   "repeatable; a candidate is interesting while they disagree as they do "
                   "on the original")
@click.option("--budget", type=str, default=None, callback=or_none(a_budget), metavar="N",
              help="with --engine, the budget of every run (default: rl1c fuzz's)")
@click.option("--out", "out", metavar="FILE", type=PATH, default=None,
              help="where the reduced program goes (default: FILE.reduced.rob beside it)")
@click.option("--sensors-out", "sensors_out", metavar="FILE", type=PATH, default=None,
              help="where the reduced sensor script goes (default: beside it, "
                   "S.reduced.json)")
@click.option("--max-tests", "max_tests", type=str, default=None, metavar="N",
              callback=or_none(at_least_one),
              help="stop after testing so many candidates, with the smallest so far "
                   f"(default {DEFAULT_MAX_TESTS})")
@click.option("--timeout", type=str, default=str(DEFAULT_TIMEOUT), metavar="SECONDS",
              callback=at_least_one, show_default=True,
              help="a test that runs longer is stopped, and the candidate is not interesting")
def reduce(file: str, sensors: str | None, command: str | None,
           engine_names: tuple[str, ...], budget: int | None, out: str | None,
           sensors_out: str | None, max_tests: int | None, timeout: int) -> int:
    """Make a program that shows a bug as small as it can be, and its sensor script.

    Lines, statements, terms and operands are deleted or made smaller (constants towards
    0), and the script's readings, losses and numbers too, while the case stays
    interesting: CMD exits 0 on it (--interesting), or the engines disagree on it as on
    the original (--engine; an engine that ends the process it runs in, as a crashing C
    VM does, is such a difference: with a C engine, each candidate is judged in a
    process of its own). Each candidate is tested once, and only if it is as well-formed
    as the original (a program the checker accepts stays so); the result is in the
    formatter's layout when it stays interesting so. The same input and command
    give the same result. The original is never changed unless --out names it. Exit
    status: 0 reduced; 1 the original is not interesting (CMD must exit 0 on it, or the
    engines disagree on it); 2 a usage problem or a file that cannot be read; 130
    Ctrl-C, the smallest case so far written."""
    from rl1.compiler.reduce import Case, NotInteresting
    from rl1.compiler.reduce import reduce as reduced

    if (command is None) == (not engine_names):
        raise click.UsageError("give --interesting CMD or --engine NAME (at least two), "
                               "one of them")
    if budget is not None and command is not None:
        raise click.UsageError("--budget goes with --engine; CMD runs what it runs")
    if file == "-" or sensors == "-":
        raise click.UsageError("the program and the script are files: the command is "
                               "given them by name")
    if sensors is not None and os.path.basename(sensors) == os.path.basename(file):
        raise click.UsageError("the program and the sensor script have one name; the "
                               "command finds them by name in one folder: rename one")
    if command is not None and not command.strip():
        raise click.UsageError("argument --interesting: the command is empty; give the "
                               "shell command that exits 0 on an interesting case")
    _check_targets(file, sensors, out, sensors_out)
    files = _read(file, sensors)
    original = Case(files.source.text, files.script)
    script = files.script
    interesting: _ShellTest | _EnginesTest
    if command is not None:
        interesting = _ShellTest(command, files, timeout)
    else:
        interesting = _engines_test(engine_names, budget, original, file, sensors)
    limit = max_tests or DEFAULT_MAX_TESTS

    def progress(name: str, case: Case, tests: int) -> None:
        print(f"rl1c reduce: {name}: {_figures(case.source)} of program"
              + (f", {_figures(case.script)} of script" if case.script is not None else "")
              + f" ({tests} tests)", file=sys.stderr)

    latest: list[Case] = []  # the last interesting candidate: the smallest so far
    tested = 0

    def remembered(case: Case) -> bool:
        nonlocal tested
        tested += 1
        found = interesting(case)
        latest[:] = [case] if found else latest
        return found

    try:
        reduction = reduced(original, remembered, max_tests=limit, progress=progress)
        case, status = reduction.case, 0
        ending = "" if reduction.finished else \
            f", stopped at --max-tests {limit} with the smallest so far"
    except NotInteresting:
        why = (f"the engines agree on {file}: nothing to reduce (a candidate is "
               "interesting while they disagree)" if not isinstance(interesting, _ShellTest)
               else f"the original is not interesting: {interesting.said()}; the command "
               "must exit 0 on the original (it runs in a new temporary folder holding "
               + " and ".join(files.names()) + ")")
        raise CommandError(why, EXIT_ERRORS) from None
    except KeyboardInterrupt:  # Ctrl-C: what was found is kept
        if not latest:
            raise
        case, status = latest[0], EXIT_INTERRUPTED
        ending = ", interrupted (Ctrl-C) with the smallest so far"
    written = _write(files, case, out, sensors_out)
    lines = [f"reduced {file}: {_figures(original.source)} -> {_figures(case.source)}"]
    if script is not None and case.script is not None:
        lines.append(f"sensor script {sensors}: {_figures(script)} -> "
                     f"{_figures(case.script)}")
    if isinstance(interesting, _EnginesTest):  # the one bug the reduction kept to
        lines.append(f"difference kept: {interesting.signature}")
    lines.append(f"{tested} tests{ending}")
    lines.append("written: " + ", ".join(written) if written else
                 "nothing smaller is interesting: nothing written")
    click.echo("\n".join(lines))
    return status


def _check_targets(file: str, sensors: str | None, out: str | None,
                   sensors_out: str | None) -> None:
    """A usage error, before any test, for an output that could not be written or would
    replace an input other than its own (--out may name the program it reduces), so that
    a reduction is never made for nothing or lost."""
    program_out = out or with_suffix(file, ".reduced.rob")
    script_out = (sensors_out or with_suffix(sensors, ".reduced.json")
                  if sensors is not None else None)
    for target, role, others in (
            (program_out, "--out", [(sensors, "the sensor script"),
                                    (script_out, "--sensors-out")]),
            (script_out, "--sensors-out", [(file, "the program")])):
        if target is None:
            continue
        if target == "-":
            raise click.UsageError(f"argument {role}: the result is written to a file: "
                                   "give its path")
        folder = os.path.dirname(os.path.abspath(target))
        problem = ("it is a folder; name a file" if os.path.isdir(target) else
                   f"there is no folder {folder}" if not os.path.isdir(folder) else
                   f"the folder {folder} is not writable; write elsewhere"
                   if not os.access(folder, os.W_OK) else
                   "it is read-only; remove it or give another path"
                   if refuses_writing(target) else None)
        for other, name in others:
            if problem is None and other is not None and (
                    os.path.abspath(other) == os.path.abspath(target)
                    or same_file(other, target)):
                problem = f"it is {name}: give each its own file"
        if problem is not None:
            raise click.UsageError(f"argument {role}: {target}: {problem}")


def _read(file: str, sensors: str | None) -> _Files:
    """The program and the script, read; a Failure (status 2) when one cannot be."""
    from rl1.compiler.frontend.source import read_source
    from rl1.compiler.runner import MAX_SCRIPT_BYTES

    try:
        source = read_source(file)
    except SourceError as error:
        raise read_failure(error, "source file") from None
    if sensors is None:
        return _Files(file, source, None, None, None)
    try:
        data = read_bounded(sensors, MAX_SCRIPT_BYTES, "a sensor script")
        return _Files(file, source, sensors, data.decode("utf-8"), data)
    except SourceError as error:
        raise read_failure(error, SCRIPT_ROLE) from None
    except UnicodeDecodeError as error:
        raise invalid_file(SCRIPT_ROLE, sensors, f"it is not UTF-8 text (byte "
                           f"{error.start})", "a sensor script is JSON or TOML") from None


@dataclass(frozen=True)
class _Files:
    """The files as read: the program's path and text, the script's path, text and
    bytes (None without one)."""

    program: str
    source: Source
    sensors: str | None
    script: str | None
    script_bytes: bytes | None

    def names(self) -> list[str]:
        return [os.path.basename(path) for path in (self.program, self.sensors) if path]

    def program_bytes(self, text: str) -> bytes:
        return encode_like(self.source, text, bom=self.source.bom)

    def sensor_bytes(self, text: str | None) -> bytes:
        """The script as written: its own bytes until the passes change it."""
        if text == self.script and self.script_bytes is not None:
            return self.script_bytes
        return (text or "").encode("utf-8")


def _figures(text: str | None) -> str:
    data = (text or "").encode()
    lines = len(data.splitlines())
    return f"{lines} line{'s' if lines != 1 else ''}, {len(data)} bytes"


def _write(files: _Files, case: Case, out: str | None, sensors_out: str | None
           ) -> list[str]:
    """Write what the reduction changed (atomically); the paths written."""
    written = []
    if case.source != files.source.text or out is not None:
        target = out or with_suffix(files.program, ".reduced.rob")
        write_file(target, files.program_bytes(case.source), role="reduced program")
        written.append(target)
    if files.sensors is not None and (case.script != files.script or sensors_out):
        target = sensors_out or with_suffix(files.sensors, ".reduced.json")
        write_file(target, files.sensor_bytes(case.script), role="reduced sensor script")
        written.append(target)
    return written


@dataclass
class _Ran:
    status: int | None  # None: stopped at the timeout
    output: bytes  # the end of what it printed, standard output and error together


class _ShellTest:
    """`command` run through the shell on each candidate, in a new temporary folder
    holding its files: interesting when it exits 0 within `timeout` seconds. Its output
    is read as it comes and only its end kept; when it ends, or is stopped, every process
    left in its process group is killed, and on Linux every process it started in a
    session of its own too (`executors.orphans_ended`)."""

    def __init__(self, command: str, files: _Files, timeout: int) -> None:
        self.command, self.files, self.timeout = command, files, timeout
        self.last: _Ran | None = None

    def __call__(self, case: Case) -> bool:
        with tempfile.TemporaryDirectory(prefix="rl1-reduce-") as folder:
            with open(os.path.join(folder, os.path.basename(self.files.program)), "wb") as out:
                out.write(self.files.program_bytes(case.source))
            if self.files.sensors is not None:
                with open(os.path.join(folder, os.path.basename(self.files.sensors)),
                          "wb") as out:
                    out.write(self.files.sensor_bytes(case.script))
            self.last = _run(self.command, folder, self.timeout)
        return self.last.status == 0

    def said(self) -> str:
        """How the last test ended, and the end of what it printed."""
        ran = self.last
        if ran is None:
            return f"`{self.command}` did not run"
        ending = (f"`{self.command}` ran longer than {self.timeout} s (--timeout)"
                  if ran.status is None else f"`{self.command}` exited with status "
                  f"{ran.status}")
        printed = ran.output.decode("utf-8", "replace").strip().splitlines()
        return ending + (f" and printed, at the end: {printed[-1][:200]}" if printed else "")


def _run(command: str, folder: str, timeout: int) -> _Ran:
    kept = bytearray()

    def read(pipe: int) -> None:
        with contextlib.suppress(OSError):
            while chunk := os.read(pipe, 1 << 16):
                kept.extend(chunk)
                del kept[:-OUTPUT_KEPT]

    with orphans_ended():
        process = subprocess.Popen(command, shell=True, cwd=folder,
                                   stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, start_new_session=True)
        assert process.stdout is not None
        reader = threading.Thread(target=read, args=(process.stdout.fileno(),), daemon=True)
        reader.start()
        try:
            status: int | None = process.wait(timeout)
        except subprocess.TimeoutExpired:
            status = None
        finally:
            # What it started is killed with it (gone already, or another user's: let be).
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    reader.join(1.0)  # a process that escaped may hold the pipe: not waited for
    if not reader.is_alive():
        process.stdout.close()
    return _Ran(status, bytes(kept))


def _engines_test(names: tuple[str, ...], budget: int | None, original: Case, file: str,
                  sensors: str | None) -> _EnginesTest:
    """The oracle of --engine: the engines named, judged as rl1c fuzz judges them."""
    from .fuzz import DEFAULT_BUDGET, needing_hypothesis

    with needing_hypothesis("rl1c reduce --engine compares engines as rl1c fuzz does,",
                            ", or use --interesting"):
        from rl1.compiler.differential import ENGINE_NAMES, engine_named
    from rl1.compiler.analysis import analyze
    from rl1.vm.scripted import parse_script
    from rl1.vm.sensor_script import ScriptError

    engines = []
    for name in names:
        engine = engine_named(name)
        if engine is None:
            raise click.UsageError(f"argument --engine: unknown engine {name!r} (choose from "
                                   f"{', '.join(ENGINE_NAMES)}, or exec:COMMAND, "
                                   "exec-O1:COMMAND, exec-O2:COMMAND)")
        engines.append(engine)
    if len({engine.name for engine in engines}) < 2:
        raise click.UsageError("argument --engine: give at least two different engines")
    if analyze(original.source).has_errors:
        raise CommandError(f"the checker finds errors in {file} (`rl1c check "
                           f"{shlex.quote(file)}` says which); the engines compare only "
                           "programs it accepts", EXIT_ERRORS)
    if sensors is not None:
        try:
            parse_script(_script_data(original.script), sensors)
        except (ValueError, RecursionError, ScriptError) as error:
            raise invalid_config(SCRIPT_ROLE, sensors, error, "with --engine the script "
                                 "is JSON, as rl1c fuzz writes it") from None
    return _EnginesTest(engines, budget or DEFAULT_BUDGET)


def _script_data(text: str | None) -> dict[str, Any]:
    """A sensor script's JSON object (ValueError when it is not one); {} for none."""
    data = json.loads(text) if text is not None else {}
    if not isinstance(data, dict):
        raise ValueError("it is not a JSON object")
    return data


class _EnginesTest:
    """Interesting while the engines disagree as on the first case tested (the
    original): the same signature, so that the reduction keeps to one bug. An engine
    that ends the process it runs in (the C VM's crash) is such a difference, its
    signal or exit status in the signature: when one could, each case is judged in a
    process forked for it, so that rl1c reduce outlives it."""

    def __init__(self, engines: list[Engine], budget: int) -> None:
        from rl1.compiler.differential import CEngine
        from rl1.vm.native import BuildError, library, load

        self.engines, self.budget = engines, budget
        self.apart = any(map(_may_end_its_process, engines))
        self.signature: str | None = None
        if any(isinstance(engine, CEngine) for engine in engines):
            # Built (or its sources hashed and its digest checked) and loaded once, here,
            # for each case forked to inherit, rather than in each (half a millisecond).
            try:
                load(library())
            except BuildError as error:  # such as no C compiler
                raise CommandError(str(error)) from None

    def __call__(self, case: Case) -> bool:
        from rl1.compiler.differential import (
            EngineUnavailable,
            judge,
            judge_apart,
            signature,
        )
        from rl1.compiler.strategies import Run
        from rl1.vm.native import BuildError

        judging = judge_apart if self.apart else judge
        try:
            verdict = judging(Run(case.source, _script_data(case.script)), self.engines,
                              self.budget)
        except (BuildError, EngineUnavailable) as error:  # such as no C compiler
            raise CommandError(str(error)) from None
        if not verdict.problems:
            return False
        found = signature(verdict)
        if self.signature is None:
            self.signature = found
        return found == self.signature


def _may_end_its_process(engine: Engine) -> bool:
    """Whether a run of `engine` could end the process it runs in: the C VM's, in it
    through ctypes, can (a crash, a sanitizer's abort), and so may any engine not known
    here; Python's engines raise instead, and the exec and batch engines run in
    processes of their own (which judge_apart drives from this one)."""
    from rl1.compiler.differential import AstEngine, VmEngine, runs_elsewhere

    return not (isinstance(engine, AstEngine | VmEngine) or runs_elsewhere(engine))


COMMANDS = (reduce,)
