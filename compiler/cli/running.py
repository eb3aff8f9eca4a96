"""What `rl1c run` and `rl1c sim` share: reading the program FILE (.rob source, or a
compiled .ilc file), running it on a device through the run stage (compiler/runner.py),
and showing why it could not run. Each command then reports the run its own way
(run_report.py, sim_report.py)."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import click

from rl1.compiler.frontend.source import Source
from rl1.compiler.reporting.render import EXIT_ERRORS, ColorChoice, FileDiagnostics
from rl1.compiler.runner import Finished, run
from rl1.vm.defaults import Engine
from rl1.vm.device import Device

from .command import CommandError
from .streams import ILC_ROLE, STDIN_NAME, emit, invalid_file, read_ilc, read_input, refused_ilc


@dataclass(frozen=True, slots=True)
class Ran:
    """A program run to its end, with the source to show its faults in: `source` is the
    text of the file `source_name` (a .rob file, or the source an .ilc file records and
    that is still the one compiled), None when it is not known."""

    finished: Finished
    source_name: str
    source: str | None


def run_file(file: str, device: Device, engine: Engine, budget: int, color: ColorChoice,
             command: str) -> Ran | int:
    """Run the program `file` on `device`; when it cannot run (errors in the source),
    its diagnostics are shown on standard error and the exit status is returned. A .rob
    file's warnings are shown first."""
    if file.lower().endswith(".ilc"):
        if engine == "ast":
            raise click.UsageError("--engine ast interprets RL/I source; an .ilc file runs "
                                   "on the VM: leave out --engine, or run the .rob file")
        data = read_ilc(file)
        with _refusals(file, data):
            finished = run(data, device, engine=engine, budget=budget)
        return Ran(finished, *_recorded_source(data, file))
    source = read_input(file)
    if not isinstance(source, Source):
        return emit([source], "human", color, command, err=True)
    with _refusals(file, None):
        outcome = run(source.text, device, engine=engine, budget=budget,
                      source_name=os.path.basename(source.name))
    if isinstance(outcome, list):  # errors: it cannot run
        return emit([FileDiagnostics(source.name, source.text, outcome)], "human", color,
                    command, err=True)
    if outcome.warnings:
        emit([FileDiagnostics(source.name, source.text, outcome.warnings)], "human", color,
             command, err=True)
    return Ran(outcome, source.name, source.text)


@contextmanager
def _refusals(file: str, data: bytes | None) -> Iterator[None]:
    """What keeps `file` from running, as the command reports it; `data`: the bytes of
    an .ilc file, None for a source compiled here (which the verifier refuses only
    through a bug of the compiler's)."""
    from rl1.vm.native import BuildError
    from rl1.vm.scripted import ScriptError
    from rl1.vm.verifier import VerifyError

    try:
        yield
    except VerifyError as error:
        if data is not None:  # as `rl1c dis` says it: text or another file named as such
            raise refused_ilc(file, data, error, "compile the program again") from None
        raise invalid_file(ILC_ROLE, STDIN_NAME if file == "-" else file,
                           f"byte {error.offset}: {error.message}",
                           "compile the program again", EXIT_ERRORS) from None
    except ScriptError as error:
        raise click.UsageError(str(error)) from None
    except BuildError as error:
        raise CommandError(str(error)) from None


def _recorded_source(data: bytes, file: str) -> tuple[str, str | None]:
    """The name and text of the source the .ilc file `file` records, when it is found
    beside it and is still the one compiled (as `dis` finds it); else `file` and None."""
    from rl1.compiler.ils.sources import find_source
    from rl1.vm import ilc

    debug = ilc.decode(data).debug
    if file == "-" or debug is None:
        return file, None
    lines = find_source(debug, file, None).lines
    if lines is None:
        return file, None
    return os.path.join(os.path.dirname(file), debug.source_name), "\n".join(lines)
