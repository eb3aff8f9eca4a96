"""The commands on intermediate code: `rl1c compile` (also `rl1c FILE.rob`), `rl1c run`,
`rl1c dis` and `rl1c asm`.

Each command imports the stages it runs when it runs, so that `rl1c check` starts
without loading the back end, the VM or the assembler (bench/cold_start.py). For the
same reason these option values are spelled here; tests/cli/test_cli_imports.py holds
them equal to driver.EMITS, runner.ENGINES and faults.DEFAULT_BUDGET.
"""

from __future__ import annotations

import os
import sys
from typing import TYPE_CHECKING

import click

from rl1.compiler.files import SourceError
from rl1.compiler.frontend.source import Source, read_source
from rl1.compiler.reporting.render import EXIT_ERRORS, ColorChoice, FileDiagnostics, Format

from .command import (
    PATH,
    Command,
    Failure,
    at_least_one,
    choice_option,
    color_option,
    force_option,
    format_option,
)
from .streams import (
    emit,
    read_ilc,
    read_input,
    same_file,
    with_suffix,
    write_file,
    write_stdout_bytes,
)

if TYPE_CHECKING:  # the back end and the engines load only for the command that runs them
    from rl1.compiler.backend.driver import Emit

    from .run import Engine

SECTION = "Intermediate code"

EMIT_CHOICES = ("ilc", "ir")
ENGINE_CHOICES = ("vm", "ast")
DEFAULT_BUDGET = 10_000_000
DEFAULT_LEVEL = 1


@click.command("compile", cls=Command)
@click.argument("file", metavar="FILE", type=PATH)
@click.option("-o", "--output", metavar="PATH", type=PATH,
              help="where to write; `-` is standard output. Default: FILE.ilc beside the "
                   "source (standard output with --emit ir)")
@click.option("-s", "--strip", is_flag=True,
              help="leave out the debug section (the map from code to source lines)")
@choice_option("--emit", "emit_kind", choices=EMIT_CHOICES, default="ilc",
               help="ilc: the .ilc file; ir: the IR as text")
@click.option("-O", "optimize", default=str(DEFAULT_LEVEL), metavar="LEVEL",
              show_default=True,
              help="optimization level: 0 none; 1 the passes whose code every format 1.0 "
                   "reader runs; 2 all of them (spec/optimization.md)")
@force_option
@format_option
@color_option
def compile_program(file: str, output: str | None, strip: bool, emit_kind: Emit,
                    optimize: str, force: bool, output_format: Format,
                    color: ColorChoice) -> int:
    """Compile an RL/I program: `rl1c FILE.rob -o FILE.ilc`.

    FILE is the RL/I program; `-` reads standard input. Diagnostics go to standard
    error; nothing is written when the program has errors. Exit status: 0 compiled
    (warnings allowed), 1 errors, 2 an unreadable input or an output that cannot be
    written."""
    from rl1.compiler.backend.driver import OPTIMIZATION_LEVELS, compile_text

    if optimize not in {str(level) for level in OPTIMIZATION_LEVELS}:
        raise click.UsageError(f"argument -O: `-O{optimize}`: the levels are "
                               + ", ".join(f"-O{level}" for level in OPTIMIZATION_LEVELS))
    if strip and emit_kind == "ir":
        raise click.UsageError("--strip drops the debug section of an .ilc file; "
                               "it has no meaning with --emit ir")
    target = output or ("-" if emit_kind == "ir" else _default_output(file))
    source = read_input(file)
    if not isinstance(source, Source):
        return emit([source], output_format, color, "compile", err=True)
    if same_file(file, target):
        raise click.UsageError(f"the output `{target}` is the source file itself: "
                               "give another path with -o")
    compilation = compile_text(source.text, os.path.basename(source.name), emit=emit_kind,
                               strip_debug=strip, level=int(optimize))
    status = emit([FileDiagnostics(source.name, source.text, compilation.diagnostics)],
                  output_format, color, "compile", err=True)
    if compilation.output is None:
        return status
    if target != "-":
        write_file(target, compilation.output, force=force)
    elif emit_kind == "ilc" and sys.stdout.isatty():
        raise click.UsageError("an .ilc file is binary and standard output is a "
                               "terminal: redirect it, or give -o FILE.ilc")
    else:
        write_stdout_bytes(compilation.output)
    return status


def _default_output(source: str) -> str:
    if source == "-":
        raise click.UsageError("reading standard input there is no file name to name the "
                               "output after: give -o FILE.ilc (or -o - for standard "
                               "output)")
    return with_suffix(source, ".ilc")


@click.command(cls=Command)
@click.argument("file", metavar="FILE", type=PATH)
@click.option("--sensors", metavar="FILE", type=PATH,
              help="sensor script for the scripted device (JSON, or TOML if FILE ends in "
                   ".toml). Without one every sensor reads 0 and the line is never lost")
@choice_option("--format", "run_format", choices=("text", "json"), default="text",
               help="text: for people; json: one object for tools")
@click.option("--budget", type=str, default=str(DEFAULT_BUDGET), callback=at_least_one,
              metavar="N", show_default=True,
              help="instructions (statements with --engine ast) before the watchdog stops "
                   "a runaway program")
@choice_option("--engine", choices=ENGINE_CHOICES, default="vm",
               help="vm: compile, then run on the reference VM; ast: interpret the source")
def run(file: str, sensors: str | None, run_format: str, budget: int, engine: Engine) -> int:
    """Run a program (.rob source, or a compiled .ilc file) on the scripted device.

    Prints the device's trace and the final variables. Exit status: 0 the program ended;
    1 it has errors (or the .ilc file is not valid); 2 a usage problem or an unreadable
    file (sensor scripts included); faults: 10 argument out of range, 11 missing handler,
    12 budget exhausted, 13 device error."""
    from rl1.vm.faults import RunResult
    from rl1.vm.scripted import Script, ScriptedDevice, ScriptError
    from rl1.vm.verifier import VerifyError

    from .run import load_script, run_ilc, run_source
    from .run_report import render_json, render_text

    try:
        device = ScriptedDevice(load_script(sensors) if sensors is not None else Script())
    except ScriptError as error:
        raise Failure(f"error: {error}") from None
    if file.lower().endswith(".ilc"):
        if engine == "ast":
            raise click.UsageError("--engine ast interprets RL/I source; an .ilc file runs "
                                   "on the VM: leave out --engine, or run the .rob file")
        data = read_ilc(file)
        try:
            result = run_ilc(data, device, budget)
        except VerifyError as error:
            raise Failure(f"error: {file}: byte {error.offset}: {error.message}",
                          EXIT_ERRORS) from None
    else:
        source = read_input(file)
        if not isinstance(source, Source):
            return emit([source], "human", "auto", "run", err=True)
        outcome = run_source(source.text, os.path.basename(source.name), device, engine,
                             budget)
        if not isinstance(outcome, RunResult):
            return emit([FileDiagnostics(source.name, source.text, outcome)], "human",
                        "auto", "run", err=True)
        result = outcome
    render = render_json if run_format == "json" else render_text
    sys.stdout.write(render(result, device.trace))
    return result.fault.kind.exit_status if result.fault is not None else 0


@click.command(cls=Command)
@click.argument("file", metavar="FILE", type=PATH)
@click.option("--source", "source_file", metavar="FILE.rob", type=PATH,
              help="the program's source, to show its lines; default: the file the .ilc "
                   "records, when it is in the .ilc file's folder")
def dis(file: str, source_file: str | None) -> int:
    """Disassemble an .ilc file into .ils text on standard output.

    The program's source lines are shown when its source file is found: the one --source
    names, or the one the .ilc records if it is in the .ilc file's folder (a recorded
    name that is absolute or leads out of the folder is not followed). Exit status: 0
    done, 1 the file is not valid intermediate code, 2 an unreadable file."""
    from rl1.compiler.ils.disasm import disassemble, named_source, source_beside
    from rl1.vm.verifier import VerifyError

    data = read_ilc(file)
    try:
        find_source = source_beside(file) if source_file is None else named_source(source_file)
    except SourceError as error:
        raise Failure(f"error: {error}") from None
    try:
        text = disassemble(data, file, find_source)
    except VerifyError as error:
        raise Failure(f"error: {file}: byte {error.offset}: {error.message}",
                      EXIT_ERRORS) from None
    sys.stdout.write(text)
    return 0


@click.command("asm", cls=Command)
@click.argument("file", metavar="FILE", type=PATH)
@click.option("-o", "--output", metavar="PATH", type=PATH,
              help="where to write the .ilc file; `-` is standard output. "
                   "Default: FILE.ilc beside the .ils file")
@force_option
def assemble_file(file: str, output: str | None, force: bool) -> int:
    """Assemble .ils text (as `rl1c dis` prints it) into an .ilc file.

    The result must pass the verifier. Exit status: 0 written, 1 errors in the text
    (nothing is written), 2 an unreadable input or an output that cannot be written."""
    from rl1.compiler.ils.asm import AsmError, assemble

    try:
        source = read_source(file)
    except SourceError as error:
        raise Failure(f"error: {error}") from None
    target = output or with_suffix(file, ".ilc")
    if same_file(file, target):
        raise click.UsageError(f"the output `{target}` is the input file itself: "
                               "give another path with -o")
    try:
        data = assemble(source.text)
    except AsmError as error:
        raise Failure("\n".join(f"{file}:{problem.line}:{problem.column}: error: "
                                f"{problem.message}" for problem in error.problems),
                      EXIT_ERRORS) from None
    if target == "-":
        write_stdout_bytes(data)
    else:
        write_file(target, data, force=force)
    return 0


COMMANDS = (compile_program, run, dis, assemble_file)
