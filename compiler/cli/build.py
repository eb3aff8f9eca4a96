"""The commands on intermediate code: `rl1c compile` (also `rl1c FILE.rob`), `rl1c run`,
`rl1c dis` and `rl1c asm`.

Each command imports the stages it runs when it runs, so that `rl1c check` starts
without loading the back end, the VM or the assembler (bench/cold_start.py); the option
defaults and choices come from rl1.vm.defaults, which imports nothing.
"""

from __future__ import annotations

import os
import sys

import click

from rl1.compiler.files import SourceError
from rl1.compiler.frontend.source import Source
from rl1.compiler.reporting.render import (
    EXIT_ERRORS,
    ColorChoice,
    FileDiagnostics,
    Format,
    use_color,
)
from rl1.vm.defaults import (
    DEFAULT_LEVEL,
    DEFAULT_TIME_LIMIT_MS,
    TRACE_CHOICES,
    Engine,
    TraceChoice,
)

from .command import (
    PATH,
    Command,
    Failure,
    budget_option,
    choice_option,
    color_option,
    engine_option,
    force_option,
    format_option,
)
from .streams import (
    PATH_ESCAPES,
    emit,
    file_failure,
    invalid_config,
    read_failure,
    read_ilc,
    read_input,
    refused_ilc,
    same_file,
    with_suffix,
    write_file,
    write_stdout_bytes,
)

SECTION = "Intermediate code"

# What --emit writes: the driver's own outputs, then the forms of the .ilc bytes
# (driver.EMITS, firmware.FORMATS and the .ils text).
EMIT_CHOICES = ("ilc", "ir", "c", "ihex", "ils")
# The file each --emit kind is written to beside the source (None: standard output).
EMIT_SUFFIXES = {"ilc": ".ilc", "ir": None, "c": ".c", "ihex": ".hex", "ils": ".ils"}
SCRIPT_ROLE = "sensor script"


def _address(ctx: click.Context, param: click.Parameter, value: str | None) -> int | None:
    """An option's callback: an address from 0 to 0xFFFFFFFF, decimal or 0x hex."""
    if value is None:
        return None
    try:
        address = int(value, 16) if value.lower().startswith("0x") else int(value, 10)
    except ValueError:
        address = -1
    if not 0 <= address <= 0xFFFF_FFFF:
        raise click.BadParameter(f"expected an address from 0 to 0xFFFFFFFF, decimal or "
                                 f"0x hex, got {value!r}", ctx, param)
    return address


@click.command("compile", cls=Command)
@click.argument("file", metavar="FILE", type=PATH)
@click.option("-o", "--output", metavar="PATH", type=PATH,
              help="where to write; `-` is standard output. Default: FILE.ilc beside the "
                   "source (FILE.c, FILE.hex or FILE.ils with --emit c, ihex or ils; "
                   "standard output with --emit ir)")
@click.option("-s", "--strip", is_flag=True,
              help="leave out the debug section (the map from code to source lines)")
@choice_option("--emit", "emit_kind", choices=EMIT_CHOICES, default="ilc",
               help="ilc: the .ilc file; ir: the IR as text; c: the .ilc bytes as a C99 "
                    "array (FILE.c); ihex: the .ilc bytes as Intel HEX (FILE.hex); ils: "
                    "the .ilc file as .ils text, as `rl1c dis` prints it (FILE.ils)")
@click.option("--c-name", metavar="NAME",
              help="with --emit c: the array's name (its size is NAME_size). "
                   "Default: the file's name and _ilc, such as sample_ilc")
@click.option("--progmem", is_flag=True,
              help="with --emit c: put the array in AVR flash (PROGMEM), for a VM built "
                   "to read it there (docs/firmware.md); on other targets it changes "
                   "nothing")
@click.option("--base-address", metavar="ADDRESS", callback=_address,
              help="with --emit ihex: the address of the first byte, decimal or 0x hex "
                   "(default 0)")
@click.option("-O", "optimize", default=str(DEFAULT_LEVEL), metavar="LEVEL",
              show_default=True,
              help="optimization level: 0 none; 1 the passes whose code every format 1.0 "
                   "reader runs; 2 all of them (spec/optimization.md)")
@force_option
@format_option
@color_option
def compile_program(file: str, output: str | None, strip: bool, emit_kind: str,
                    c_name: str | None, progmem: bool, base_address: int | None,
                    optimize: str, force: bool, output_format: Format,
                    color: ColorChoice) -> int:
    """Compile an RL/I program: `rl1c FILE.rob -o FILE.ilc`.

    FILE is the RL/I program; `-` reads standard input. With --emit, the same code in
    another form: a C array or Intel HEX for a firmware build, .ils text. Diagnostics go
    to standard error; nothing is written when the program has errors. Exit status: 0
    compiled (warnings allowed), 1 errors, 2 an unreadable input or an output that
    cannot be written."""
    from rl1.compiler.backend.driver import OPTIMIZATION_LEVELS, compile_text
    from rl1.compiler.ils.sources import recorded_name

    if optimize not in {str(level) for level in OPTIMIZATION_LEVELS}:
        raise click.UsageError(f"argument -O: `-O{optimize}`: the levels are "
                               + ", ".join(f"-O{level}" for level in OPTIMIZATION_LEVELS))
    if strip and emit_kind == "ir":
        raise click.UsageError("--strip drops the debug section of an .ilc file; "
                               "it has no meaning with --emit ir")
    _check_form_options(emit_kind, c_name, progmem, base_address)
    target = output or _default_output(file, emit_kind)
    source = read_input(file)
    if not isinstance(source, Source):
        return emit([source], output_format, color, "compile", err=True)
    if same_file(file, target):
        raise click.UsageError(f"the output `{target}` is the source file itself: "
                               "give another path with -o")
    compilation = compile_text(source.text, recorded_name(source.name, target),
                               emit="ir" if emit_kind == "ir" else "ilc",
                               strip_debug=strip, level=int(optimize))
    status = emit([FileDiagnostics(source.name, source.text, compilation.diagnostics)],
                  output_format, color, "compile", err=True)
    if compilation.output is None:
        return status
    data = compilation.output
    if emit_kind not in ("ilc", "ir"):
        name = c_name or _c_name_for(file if file != "-" else target)
        data = _ilc_form(emit_kind, data, source, name, progmem, base_address or 0)
    if target != "-":
        write_file(target, data, force=force)
    elif emit_kind == "ilc" and sys.stdout.isatty():
        raise click.UsageError("an .ilc file is binary and standard output is a "
                               "terminal: redirect it, or give -o FILE.ilc")
    else:
        write_stdout_bytes(data)
    return status


def _check_form_options(emit_kind: str, c_name: str | None, progmem: bool,
                        base_address: int | None) -> None:
    from rl1.compiler.backend.firmware import c_name_problem

    if c_name is not None and emit_kind != "c":
        raise click.UsageError("--c-name names the array of --emit c: give --emit c, or "
                               "leave out --c-name")
    if progmem and emit_kind != "c":
        raise click.UsageError("--progmem places the array of --emit c: give --emit c, "
                               "or leave out --progmem")
    if base_address is not None and emit_kind != "ihex":
        raise click.UsageError("--base-address places the bytes of --emit ihex: give "
                               "--emit ihex, or leave out --base-address")
    problem = c_name_problem(c_name) if c_name is not None else None
    if problem is not None:
        raise click.UsageError(f"argument --c-name: {problem}")


def _c_name_for(path: str) -> str:
    from rl1.compiler.backend.firmware import c_name_for

    return c_name_for(os.path.splitext(os.path.basename(path))[0] if path != "-" else "")


def _ilc_form(emit_kind: str, data: bytes, source: Source, c_name: str, progmem: bool,
              base: int) -> bytes:
    """The .ilc bytes `data` of `source` in the form --emit asks for."""
    from rl1.compiler.backend import firmware
    from rl1.compiler.ils.disasm import disassemble

    if emit_kind == "c":
        return firmware.c_source(data, c_name, os.path.basename(source.name),
                                 progmem).encode("ascii")
    if emit_kind == "ihex":
        try:
            return firmware.intel_hex(data, base).encode("ascii")
        except ValueError as error:
            raise click.UsageError(f"argument --base-address: {error}") from None
    name = with_suffix(os.path.basename(source.name), ".ilc")
    return disassemble(data, name, source.lines).encode("utf-8", PATH_ESCAPES)


def _default_output(source: str, emit_kind: str) -> str:
    suffix = EMIT_SUFFIXES[emit_kind]
    if suffix is None:
        return "-"
    if source == "-":
        raise click.UsageError("reading standard input there is no file name to name the "
                               f"output after: give -o FILE{suffix} (or -o - for standard "
                               "output)")
    return with_suffix(source, suffix)


def _time_limit(ctx: click.Context, param: click.Parameter, value: str) -> int:
    """An option's callback: a device-time limit in seconds (a decimal number, down to
    the millisecond) as milliseconds, from 1 ms to MAX_BUDGET ms (24.8 days)."""
    from rl1.vm.faults import MAX_BUDGET

    try:
        milliseconds = round(float(value) * 1000)
    except (ValueError, OverflowError):
        milliseconds = 0
    if not 1 <= milliseconds <= MAX_BUDGET:
        raise click.BadParameter(f"expected seconds from 0.001 to {MAX_BUDGET // 1000}, "
                                 f"got {value!r}", ctx, param)
    return milliseconds


@click.command(cls=Command)
@click.argument("file", metavar="FILE", type=PATH, required=False)
@click.option("--sensors", metavar="FILE", type=PATH,
              help="the sensor script: what each sensing call reads and when the line is "
                   "lost (JSON, or TOML if FILE ends in .toml; spec/sensors.md). Without one "
                   "the first sensing call stops the run")
@choice_option("--format", "run_format", choices=("text", "json"), default="text",
               help="text: for people; json: one object for tools (spec/sensors.md)")
@choice_option("--trace", "trace_choice", choices=TRACE_CHOICES, default=None,
               help="which entries of the device's trace to show: short: the first 40 and "
                    "the last 20 of a longer trace, with how many were left out; all: every "
                    "one; calls: the program's calls only (no lost line, no stop); none. "
                    "Default: short with --format text, all with json")
@budget_option
@click.option("--time-limit", type=str, default=f"{DEFAULT_TIME_LIMIT_MS / 1000:g}",
              callback=_time_limit,
              metavar="SECONDS", show_default=True,
              help="device time before the run is stopped (a device error): a program "
                   "waiting in a loop for a reading that never comes")
@engine_option
@click.option("--batch", is_flag=True,
              help="instead of FILE, run one .ilc file after another as `rl1c fuzz`'s "
                   "exec-batch: engines do: a JSON job a line on standard input, the run "
                   "a line on standard output (spec/optimization.md, section 5)")
@color_option
def run(file: str | None, sensors: str | None, run_format: str,
        trace_choice: TraceChoice | None, budget: int, time_limit: int, engine: Engine,
        batch: bool, color: ColorChoice) -> int:
    """Run a program (.rob source, or a compiled .ilc file) on the scripted device.

    Prints the device's trace with the source line of each entry, how the run ended and
    the final variables; a .rob file's warnings come first, on standard error. The
    sensor script's format: spec/sensors.md. Exit status: 0 the program ended; 1 it has
    errors (or the .ilc file is not valid); 2 a usage problem or an unreadable file
    (sensor scripts included); faults: 10 argument out of range, 11 missing handler, 12
    budget exhausted, 13 device error (a sensing call past the script's readings, the
    time limit)."""
    from rl1.compiler.files import SourceError
    from rl1.compiler.runner import load_script
    from rl1.vm.scripted import Script, ScriptedDevice, ScriptError

    from .run_report import RunReport, render_json, render_text, select_trace
    from .running import run_file

    if batch:
        if file is not None or sensors is not None or engine == "ast":
            raise click.UsageError("--batch reads its programs and scripts from standard "
                                   "input, and runs them on a VM: give it without FILE, "
                                   "--sensors and --engine ast")
        from .run_batch import serve

        return serve(sys.stdin.buffer, sys.stdout, engine, time_limit)
    if file is None:
        raise click.UsageError("Missing argument 'FILE'.")
    script = Script()
    if sensors is not None:
        try:
            script = load_script(sensors)
        except SourceError as error:
            raise read_failure(error, SCRIPT_ROLE) from None
        except ScriptError as error:
            raise invalid_config(SCRIPT_ROLE, sensors, error,
                                 "correct it as spec/sensors.md describes") from None
    device = ScriptedDevice(script, time_limit)
    ran = run_file(file, device, engine, budget, color, "run")
    if isinstance(ran, int):
        return ran
    result = ran.finished.result
    report = RunReport(file, ran.source_name, ran.source, result,
                       select_trace(device.log, trace_choice or
                                    ("short" if run_format == "text" else "all")),
                       ran.finished.instructions, device.time,
                       device.motion if result.fault is None else None,
                       device.losses_not_met())
    if run_format == "json":
        sys.stdout.write(render_json(report))
    else:
        sys.stdout.write(render_text(report, color=use_color(color, sys.stdout)))
    return result.fault.kind.exit_status if result.fault is not None else 0


@click.command(cls=Command)
@click.argument("file", metavar="FILE", type=PATH)
@click.option("--source", "source_file", metavar="FILE.rob", type=PATH,
              help="the program's source, to show its lines; default: the file the .ilc "
                   "records (a path from its folder), when its digest is the one recorded")
def dis(file: str, source_file: str | None) -> int:
    """Disassemble an .ilc file (`-`: standard input) into .ils text on standard output.

    The program's source lines are shown when its source file is found (the one
    --source names, or the relative path the .ilc records, from the .ilc file's folder,
    to a regular file; an absolute one is not followed) and is the source that was
    compiled: its digest is the one the .ilc records (a file without one, format 1.0,
    takes its source only from --source). Why no lines are shown is said on standard
    error. Exit status: 0 done, 1 the file is not valid intermediate code, 2 an
    unreadable file."""
    from rl1.compiler.ils.disasm import disassemble
    from rl1.compiler.ils.sources import find_source
    from rl1.vm.verifier import VerifyError, verify

    data = read_ilc(file)
    try:
        debug = verify(data).image.debug  # an invalid file is refused before any source is read
    except VerifyError as error:
        raise refused_ilc(file, data, error, "compile the program again, or assemble it "
                                             "with `rl1c asm`") from None
    try:
        found = find_source(debug, file, source_file)
    except SourceError as error:
        raise read_failure(error, "--source file") from None
    if found.note is not None:
        click.echo(found.note, err=True)
    sys.stdout.write(disassemble(data, file, found.lines))
    return 0


@click.command("asm", cls=Command)
@click.argument("file", metavar="FILE", type=PATH)
@click.option("-o", "--output", metavar="PATH", type=PATH,
              help="where to write the .ilc file; `-` is standard output. "
                   "Default: FILE.ilc beside the .ils file")
@force_option
def assemble_file(file: str, output: str | None, force: bool) -> int:
    """Assemble .ils text (as `rl1c dis` prints it; `-`: standard input) into an .ilc file.

    The result must pass the verifier. Exit status: 0 written, 1 errors in the text
    (nothing is written), 2 an unreadable input or an output that cannot be written."""
    from rl1.compiler.ils.asm import AsmError, assemble

    source = read_input(file, ".ils file")
    if not isinstance(source, Source):
        raise file_failure(source)
    target = output or _default_output(file, "ilc")
    if same_file(file, target):
        raise click.UsageError(f"the output `{target}` is the input file itself: "
                               "give another path with -o")
    try:
        data = assemble(source.text)
    except AsmError as error:
        raise Failure("\n".join(f"{source.name}:{problem.line}:{problem.column}: error: "
                                f"{problem.message}" for problem in error.problems),
                      EXIT_ERRORS) from None
    if target == "-":
        write_stdout_bytes(data)
    else:
        write_file(target, data, force=force)
    return 0


COMMANDS = (compile_program, run, dis, assemble_file)
