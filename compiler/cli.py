"""`rl1c`: compile RL/I (`rl1c FILE.rob -o FILE.ilc`) and the actions beside it.

Each action is a thin wrapper: parse options, call the stage that does the work, map the
outcome to an exit status. Exit statuses: 0 success, 1 the input has errors,
2 a usage problem or an unreadable file, 3 an internal error (a bug in rl1c).

To add a command: one function decorated `@main.command()`; read inputs with
`read_input`, report diagnostics with `emit` (or render.report), end with `ctx.exit`.
"""

from __future__ import annotations

import os
import sys
import traceback
from pathlib import Path
from typing import TYPE_CHECKING

import click

from rl1.vm.faults import DEFAULT_BUDGET

from .ast import Span
from .diagnostics import Diagnostic, Severity
from .render import (
    COLOR_CHOICES,
    EXIT_ERRORS,
    EXIT_USAGE,
    FORMATS,
    ColorChoice,
    FileDiagnostics,
    Format,
    exit_status,
    report,
    use_color,
)
from .source import MAX_SOURCE_BYTES, Source, SourceError, decode, read_source

if TYPE_CHECKING:
    from rl1.vm.runner import Engine

    from .driver import Emit

# Each command imports the stages it runs when it runs, so that `rl1c check` starts
# without loading the back end, the VM or the assembler (bench/cold_start.py). For the
# same reason these option choices are spelled here; tests/test_cli_imports.py holds
# them equal to driver.EMITS and runner.ENGINES.
EMIT_CHOICES = ("ilc", "ir")
ENGINE_CHOICES = ("vm", "ast")

EXIT_INTERNAL = 3

STDIN_NAME = "<stdin>"


class _Toolchain(click.Group):
    """The `rl1c` group: `rl1c FILE ...` means `rl1c compile FILE ...`, so compiling
    needs no verb; and an unexpected exception ends in a short message, not a traceback."""

    def resolve_command(
        self, ctx: click.Context, args: list[str]
    ) -> tuple[str | None, click.Command | None, list[str]]:
        if args and args[0] not in self.commands and (args[0] == "-"  # standard input
                                                      or not args[0].startswith("-")):
            args = ["compile", *args]
        return super().resolve_command(ctx, args)

    def invoke(self, ctx: click.Context) -> object:
        try:
            return super().invoke(ctx)
        except (click.exceptions.Exit, click.ClickException, click.Abort, BrokenPipeError):
            raise  # click turns these into their messages and exit statuses
        except Exception as error:
            # A traceback tells a robot programmer nothing they can act on and reads as
            # if their program were at fault; a distinct status (3) lets scripts and CI
            # tell a bug in rl1c from a program with errors (1) or a usage problem (2).
            # RL1C_BACKTRACE=1 shows the traceback to whoever debugs rl1c.
            if os.environ.get("RL1C_BACKTRACE"):
                traceback.print_exc()
            summary = f"{type(error).__name__}: {error}"
            click.echo(
                f"rl1c: internal error: {summary[:300]}\n"
                "This is a bug in rl1c, not in your program. Please report it with the "
                "command line and the input file (RL1C_BACKTRACE=1 shows the details).",
                err=True,
            )
            ctx.exit(EXIT_INTERNAL)


@click.group(cls=_Toolchain, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="rl1", prog_name="rl1c")
def main() -> None:
    """The RL/I toolchain. `rl1c FILE.rob -o FILE.ilc` compiles; the commands below
    check, format, explain, disassemble, assemble and run programs."""
    # A terminal that cannot show a character (a Japanese comment in a Latin-1 locale)
    # gets an escape for it instead of a failure.
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is not None:
            reconfigure(errors="backslashreplace")


# Shared by the commands that report diagnostics.
format_option = click.option(
    "--format", "output_format", type=click.Choice(FORMATS), default="human",
    show_default=True, help="human: text for people; json or sarif: for tools.",
)
color_option = click.option(
    "--color", "color", type=click.Choice(COLOR_CHOICES), default="auto", show_default=True,
    help="Colour the human format; auto: only on a terminal, and not if NO_COLOR is set.",
)


def read_input(name: str) -> Source | FileDiagnostics:
    """The source file `name` (`-` is standard input), or the E0100 report of why it
    cannot be read."""
    try:
        if name != "-":
            return read_source(name)
        data = sys.stdin.buffer.read(MAX_SOURCE_BYTES + 1)
        if len(data) > MAX_SOURCE_BYTES:
            raise SourceError(f"{STDIN_NAME} holds more than {MAX_SOURCE_BYTES} bytes; "
                              "RL/I sources are limited to that size")
        return decode(data, STDIN_NAME)
    except SourceError as error:
        unreadable = Diagnostic("E0100", Severity.ERROR, str(error), Span(1, 1, 1, 1))
        return FileDiagnostics(STDIN_NAME if name == "-" else name, None, [unreadable])


def emit(files: list[FileDiagnostics], output_format: Format, color: ColorChoice,
         action: str, *, err: bool = False) -> int:
    """Print the diagnostics of `files` on standard output (`err`: standard error);
    the exit status they call for."""
    colored = output_format == "human" and use_color(color, sys.stderr if err else sys.stdout)
    click.echo(report(files, output_format, color=colored, action=action), nl=False,
               err=err, color=colored)
    return exit_status(files)


@main.command()
@click.argument("files", nargs=-1, required=True)
@format_option
@color_option
@click.pass_context
def check(ctx: click.Context, files: tuple[str, ...], output_format: Format,
          color: ColorChoice) -> None:
    """Check RL/I programs (`-` reads standard input) and report every problem found.
    Exit status: 0 no errors (warnings allowed), 1 errors, 2 an unreadable file."""
    from .frontend import analyze

    checked: list[FileDiagnostics] = []
    for name in files:
        source = read_input(name)
        if isinstance(source, Source):
            checked.append(FileDiagnostics(source.name, source.text,
                                           analyze(source.text).diagnostics))
        else:
            checked.append(source)
    ctx.exit(emit(checked, output_format, color, "check"))


@main.command("compile")
@click.argument("file")
@click.option("-o", "--output", metavar="PATH",
              help="Where to write; `-` is standard output. Default: FILE.ilc beside the "
                   "source (standard output with --emit ir).")
@click.option("-s", "--strip", is_flag=True,
              help="Leave out the debug section (the map from code to source lines).")
@click.option("--emit", "emit_kind", type=click.Choice(EMIT_CHOICES), default="ilc",
              show_default=True, help="ilc: the .ilc file; ir: the IR as text.")
@click.option("-O", "optimize", default="0", metavar="LEVEL",
              help="Optimization level; only -O0 (none) exists so far.")
@format_option
@color_option
@click.pass_context
def compile_program(ctx: click.Context, file: str, output: str | None, strip: bool,
                    emit_kind: Emit, optimize: str, output_format: Format,
                    color: ColorChoice) -> None:
    """Compile an RL/I program (`-` reads standard input): `rl1c FILE.rob -o FILE.ilc`.
    Diagnostics go to standard error; nothing is written when the program has errors.
    Exit status: 0 compiled (warnings allowed), 1 errors, 2 an unreadable input or an
    output that cannot be written."""
    from .atomic import write_atomically
    from .driver import OPTIMIZATION_LEVELS, compile_text

    if optimize not in {str(level) for level in OPTIMIZATION_LEVELS}:
        raise click.BadParameter(f"`-O{optimize}`: only -O0 (no optimization) exists so far",
                                 param_hint="-O")
    if strip and emit_kind == "ir":
        raise click.UsageError("--strip drops the debug section of an .ilc file; "
                               "it has no meaning with --emit ir")
    target = output or ("-" if emit_kind == "ir" else _default_output(file))
    source = read_input(file)
    if not isinstance(source, Source):
        ctx.exit(emit([source], output_format, color, "compile", err=True))
    if target != "-" and file != "-" and os.path.exists(target) \
            and os.path.samefile(file, target):
        raise click.UsageError(f"the output `{target}` is the source file itself: "
                               "give another path with -o")
    compilation = compile_text(source.text, Path(source.name).name, emit=emit_kind,
                               strip_debug=strip)
    status = emit([FileDiagnostics(source.name, source.text, compilation.diagnostics)],
                  output_format, color, "compile", err=True)
    if compilation.output is None:
        ctx.exit(status)
    if target == "-":
        stdout = sys.stdout.buffer
        if emit_kind == "ilc" and stdout.isatty():
            raise click.UsageError("an .ilc file is binary and standard output is a "
                                   "terminal: redirect it, or give -o FILE.ilc")
        stdout.write(compilation.output)
        stdout.flush()
        return
    try:
        write_atomically(target, compilation.output)
    except OSError as error:
        click.echo(f"error: cannot write `{target}`: {error.strerror or error}", err=True)
        ctx.exit(EXIT_USAGE)


def _default_output(source: str) -> str:
    if source == "-":
        raise click.UsageError("reading standard input there is no file name to name the "
                               "output after: give -o FILE.ilc (or -o - for standard output)")
    return str(Path(source).with_suffix(".ilc"))


@main.command()
@click.argument("code", required=False)
@click.option("--list", "list_codes", is_flag=True, help="List every code with its title.")
@click.pass_context
def explain(ctx: click.Context, code: str | None, list_codes: bool) -> None:
    """Explain a diagnostic code in depth, with examples: `rl1c explain E0101`."""
    from .catalogue import CODES

    if list_codes == (code is not None):
        raise click.UsageError("give a code, as in `rl1c explain E0101`, or --list")
    if code is None:
        for entry in CODES.values():
            click.echo(f"{entry.code}  {entry.title}")
        return
    info = CODES.get(code.strip().upper())
    if info is None:
        click.echo(f"error: `{code}` is not a diagnostic code of rl1c\n"
                   "  = help: `rl1c explain --list` lists every code with its title",
                   err=True)
        ctx.exit(EXIT_USAGE)
    click.echo(info.explanation(), nl=False)


MAX_ILC_BYTES = 16 * 1024 * 1024  # far more than any .ilc file holds


def read_ilc(ctx: click.Context, file: str) -> bytes:
    """The bytes of an .ilc file; exits 2 when it cannot be read, 1 when it is too large
    to be one (without reading a huge file whole)."""
    try:
        with open(file, "rb") as stream:
            data = stream.read(MAX_ILC_BYTES + 1)
    except OSError as error:
        click.echo(f"error: cannot read `{file}`: {error.strerror or error}", err=True)
        ctx.exit(EXIT_USAGE)
    if len(data) > MAX_ILC_BYTES:
        click.echo(f"error: `{file}` is larger than {MAX_ILC_BYTES} bytes: not an .ilc file",
                   err=True)
        ctx.exit(EXIT_ERRORS)
    return data


@main.command()
@click.argument("file")
@click.pass_context
def dis(ctx: click.Context, file: str) -> None:
    """Disassemble an .ilc file into .ils text on standard output, with the program's
    source lines when its source file is found (beside the .ilc, or by the recorded name).
    Exit status: 0 done, 1 the file is not valid intermediate code, 2 an unreadable file."""
    from rl1.vm.verifier import VerifyError

    from .disasm import disassemble, source_beside

    data = read_ilc(ctx, file)
    try:
        text = disassemble(data, file, source_beside(file))
    except VerifyError as error:
        click.echo(f"error: {file}: byte {error.offset}: {error.message}", err=True)
        ctx.exit(EXIT_ERRORS)
    click.echo(text, nl=False)


@main.command("asm")
@click.argument("file")
@click.option("-o", "--output", metavar="PATH",
              help="Where to write the .ilc file; `-` is standard output. "
                   "Default: FILE.ilc beside the .ils file.")
@click.pass_context
def assemble_file(ctx: click.Context, file: str, output: str | None) -> None:
    """Assemble .ils text (as `rl1c dis` prints it) into an .ilc file; the result must
    pass the verifier. Exit status: 0 written, 1 errors in the text (nothing is written),
    2 an unreadable input or an output that cannot be written."""
    from .asm import AsmError, assemble
    from .atomic import write_atomically

    try:
        source = read_source(file)
    except SourceError as error:
        click.echo(f"error: {error}", err=True)
        ctx.exit(EXIT_USAGE)
    target = output or str(Path(file).with_suffix(".ilc"))
    if target != "-" and os.path.exists(target) and os.path.samefile(file, target):
        raise click.UsageError(f"the output `{target}` is the input file itself: "
                               "give another path with -o")
    try:
        data = assemble(source.text)
    except AsmError as error:
        for problem in error.problems:
            click.echo(f"{file}:{problem.line}:{problem.column}: error: {problem.message}",
                       err=True)
        ctx.exit(EXIT_ERRORS)
    if target == "-":
        sys.stdout.buffer.write(data)
        return
    try:
        write_atomically(target, data)
    except OSError as error:
        click.echo(f"error: cannot write `{target}`: {error.strerror or error}", err=True)
        ctx.exit(EXIT_USAGE)


@main.command("fmt")
@click.argument("files", nargs=-1, required=True)
@click.option("--check", is_flag=True,
              help="Change nothing; list the files formatting would change (exit status 1).")
@click.option("--diff", is_flag=True,
              help="Change nothing; print what formatting would change as a unified diff.")
@click.pass_context
def fmt(ctx: click.Context, files: tuple[str, ...], check: bool, diff: bool) -> None:
    """Put RL/I programs in the canonical layout (spec/language.md, section 11), rewriting
    each file in place in its own encoding; `-` formats standard input to standard output.
    Exit status: 0 done, 1 (--check) a file would change, 2 a file cannot be read or
    written."""
    from . import formatter

    status = 0
    for name in files:
        source = read_input(name)
        if not isinstance(source, Source):
            emit([source], "human", "auto", "format", err=True)
            status = EXIT_USAGE
            continue
        formatted = formatter.format_text(source.text)
        changed = formatted != source.text
        if diff and changed:
            click.echo(formatter.unified_diff(source.name, source.text, formatted), nl=False)
        if check and changed:
            click.echo(source.name)
            status = max(status, EXIT_ERRORS)
        if check or diff:
            continue
        if name == "-":
            sys.stdout.buffer.write(formatter.encode_like(source, formatted, bom=False))
        elif changed:
            try:
                formatter.rewrite(source, formatted)
            except OSError as error:
                click.echo(f"error: cannot write `{name}`: {error.strerror or error}", err=True)
                status = EXIT_USAGE
    ctx.exit(status)


@main.command()
@click.argument("file")
@click.option("--sensors", metavar="FILE",
              help="Sensor script for the scripted device (JSON, or TOML if FILE ends in "
                   ".toml). Without one every sensor reads 0 and the line is never lost.")
@click.option("--format", "run_format", type=click.Choice(("text", "json")), default="text",
              show_default=True, help="text: for people; json: one object for tools.")
@click.option("--budget", type=click.IntRange(min=1), default=DEFAULT_BUDGET,
              show_default=True,
              help="Instructions (statements with --engine ast) before the watchdog stops "
                   "a runaway program.")
@click.option("--engine", type=click.Choice(ENGINE_CHOICES), default="vm", show_default=True,
              help="vm: compile, then run on the reference VM; ast: interpret the source.")
@click.pass_context
def run(ctx: click.Context, file: str, sensors: str | None, run_format: str, budget: int,
        engine: Engine) -> None:
    """Run a program (.rob source, or a compiled .ilc file) on the scripted device; print
    the device's trace and the final variables. Exit status: 0 the program ended; 1 it
    has errors (or the .ilc file is not valid); 2 a usage problem or an unreadable file
    (sensor scripts included); faults: 10 argument out of range, 11 missing handler,
    12 budget exhausted, 13 device error."""
    from rl1.vm.faults import RunResult
    from rl1.vm.report import render_json, render_text
    from rl1.vm.runner import run_ilc, run_source
    from rl1.vm.scripted import Script, ScriptedDevice, ScriptError, load_script
    from rl1.vm.verifier import VerifyError

    try:
        device = ScriptedDevice(load_script(sensors) if sensors is not None else Script())
    except ScriptError as error:
        click.echo(f"error: {error}", err=True)
        ctx.exit(EXIT_USAGE)
    if file.lower().endswith(".ilc"):
        if engine == "ast":
            raise click.UsageError("--engine ast interprets RL/I source; an .ilc file runs "
                                   "on the VM: leave out --engine, or run the .rob file")
        data = read_ilc(ctx, file)
        try:
            result = run_ilc(data, device, budget)
        except VerifyError as error:
            click.echo(f"error: {file}: byte {error.offset}: {error.message}", err=True)
            ctx.exit(EXIT_ERRORS)
    else:
        source = read_input(file)
        if not isinstance(source, Source):
            ctx.exit(emit([source], "human", "auto", "run", err=True))
        outcome = run_source(source.text, Path(source.name).name, device, engine, budget)
        if not isinstance(outcome, RunResult):
            ctx.exit(emit([FileDiagnostics(source.name, source.text, outcome)], "human",
                          "auto", "run", err=True))
        result = outcome
    render = render_json if run_format == "json" else render_text
    click.echo(render(result, device.trace), nl=False)
    ctx.exit(result.fault.kind.exit_status if result.fault is not None else 0)
