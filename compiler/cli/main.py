"""`rl1c`: compile RL/I (`rl1c FILE.rob -o FILE.ilc`) and the actions beside it.

Each action is a thin wrapper: parse options, call the stage that does the work, map the
outcome to an exit status. Exit statuses: 0 success, 1 the input has errors,
2 a usage problem or an unreadable file, 3 an internal error (a bug in rl1c).

To add a command: a function returning the exit status, decorated `@command(name,
*arguments)` with the arguments it takes as keywords; its docstring is its help, the
first line its summary in `rl1c --help`. Read inputs with `read_input`, report
diagnostics with `emit` (or render.report), and end early by raising `Failure` (a message
for standard error and a status) or `UsageError`.

The command line is built on the standard library's argparse rather than click:
`rl1c check` must start within twice the time of `python -c pass`
(bench/cold_start.py), and importing click alone takes that whole budget (30 ms).
"""

from __future__ import annotations

import argparse
import os
import sys

from rl1.compiler.files import SourceError
from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity
from rl1.compiler.frontend.source import MAX_SOURCE_BYTES, Source, decode, read_source
from rl1.compiler.reporting.render import (
    COLOR_CHOICES,
    EXIT_ERRORS,
    EXIT_USAGE,
    FORMATS,
    FileDiagnostics,
    exit_status,
    report,
    use_color,
)

TYPE_CHECKING = False  # `typing` costs 4 ms of every start (record.py)
if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any, TypeVar

    from rl1.compiler.backend.driver import Emit
    from rl1.compiler.reporting.render import ColorChoice, Format

    from .run import Engine

    Run = TypeVar("Run", bound=Callable[..., int])
    Argument = tuple[tuple[str, ...], dict[str, Any]]

# Each command imports the stages it runs when it runs, so that `rl1c check` starts
# without loading the back end, the VM or the assembler (bench/cold_start.py). For the
# same reason these option values are spelled here; tests/test_cli_imports.py holds
# them equal to driver.EMITS, runner.ENGINES and faults.DEFAULT_BUDGET.
EMIT_CHOICES = ("ilc", "ir")
ENGINE_CHOICES = ("vm", "ast")
DEFAULT_BUDGET = 10_000_000

EXIT_INTERNAL = 3
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report a program stopped by Ctrl-C

STDIN_NAME = "<stdin>"

DESCRIPTION = """The RL/I toolchain. `rl1c FILE.rob -o FILE.ilc` compiles; the commands
below check, format, explain, disassemble, assemble and run programs."""


class UsageError(Exception):
    """The command line asks for something impossible; shown with the command's usage,
    exit status 2."""


class Failure(Exception):
    """Ends a command: `message` goes to standard error, `status` is the exit status."""

    def __init__(self, message: str, status: int = EXIT_USAGE) -> None:
        super().__init__(message)
        self.status = status


def main(argv: list[str] | None = None) -> int:
    """Runs the command line `argv` (default: the process's arguments); the exit status.
    Asking for help or the version, or a malformed command line, ends in SystemExit."""
    _escape_unprintable_output()
    args = _with_verb(sys.argv[1:] if argv is None else argv)
    if not args or args[0] not in _COMMANDS:
        return _toolchain(args)
    function, arguments = _COMMANDS[args[0]]
    # The parser of this command only: building every command's would take 4 ms.
    command_parser = _parser(f"rl1c {args[0]}", function.__doc__)
    for names, settings in arguments:
        command_parser.add_argument(*names, **settings)
    # Intermixed: options may come between files, `rl1c check a.rob --format json b.rob`.
    options = vars(command_parser.parse_intermixed_args(args[1:]))
    try:
        status = function(**options)
        sys.stdout.flush()  # a closed pipe shows here, not when the process exits
        return status
    except UsageError as error:
        command_parser.print_usage(sys.stderr)
        print(f"{command_parser.prog}: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except Failure as failure:
        print(failure, file=sys.stderr)
        return failure.status
    except BrokenPipeError:
        # The reader stopped early (`rl1c dis x.ilc | head`): end quietly. What is left in
        # the buffer goes to /dev/null, or Python would fail again flushing it at exit.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_ERRORS
    except KeyboardInterrupt:
        print("rl1c: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as error:
        return _internal_error(error)


def _internal_error(error: Exception) -> int:
    # A traceback tells a robot programmer nothing they can act on and reads as if their
    # program were at fault; a distinct status (3) lets scripts and CI tell a bug in rl1c
    # from a program with errors (1) or a usage problem (2). RL1C_BACKTRACE=1 shows the
    # traceback to whoever debugs rl1c.
    if os.environ.get("RL1C_BACKTRACE"):
        import traceback

        traceback.print_exception(error)
    summary = f"{type(error).__name__}: {error}"
    print(f"rl1c: internal error: {summary[:300]}\n"
          "This is a bug in rl1c, not in your program. Please report it with the command "
          "line and the input file (RL1C_BACKTRACE=1 shows the details).", file=sys.stderr)
    return EXIT_INTERNAL


def _escape_unprintable_output() -> None:
    # A terminal that cannot show a character (a Japanese comment in a Latin-1 locale)
    # gets an escape for it instead of a failure.
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is not None:
            reconfigure(errors="backslashreplace")


def _with_verb(args: list[str]) -> list[str]:
    """`rl1c FILE ...` means `rl1c compile FILE ...`: compiling needs no verb."""
    if args and args[0] not in _COMMANDS and (args[0] == "-"  # standard input
                                              or not args[0].startswith("-")):
        return ["compile", *args]
    return args


# Declaring commands ---------------------------------------------------------------------

_COMMANDS: dict[str, tuple[Callable[..., int], Sequence[Argument]]] = {}


def command(name: str, *arguments: Argument) -> Callable[[Run], Run]:
    """Makes the decorated function the command `name`, called with `arguments` (made by
    `argument`) as keywords."""
    def register(function: Run) -> Run:
        _COMMANDS[name] = (function, arguments)
        return function
    return register


def argument(*names: str, **settings: Any) -> Argument:
    """An argument of a command, as argparse's `add_argument` takes it."""
    return names, settings


def _toolchain(args: list[str]) -> int:
    """`rl1c` without a command: --help, --version, or a usage problem (no arguments at
    all is one: the help goes to standard error)."""
    parser = _parser("rl1c", DESCRIPTION)
    parser.add_argument("--version", action=_ShowVersion, help="show the version and exit")
    commands = parser.add_subparsers(title="commands", metavar="COMMAND")
    for name, (function, _) in _COMMANDS.items():
        commands.add_parser(name, help=(function.__doc__ or "").partition("\n")[0])
    if not args:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    parser.parse_args(args)  # --help and --version end the process, and errors
    parser.error("expected a command, or a file to compile (see rl1c --help)")


def _parser(prog: str, description: str | None) -> argparse.ArgumentParser:
    # No abbreviated options (`--form` for `--format`): adding an option could break them.
    return argparse.ArgumentParser(prog=prog, description=description, allow_abbrev=False,
                                   formatter_class=_HelpFormatter)


class _HelpFormatter(argparse.HelpFormatter):
    """argparse's help layout, given the terminal's width. Left to find it, argparse
    imports shutil (and with it bz2, lzma and zlib: 3 ms of every start), because it
    makes a formatter for every argument added, to check its metavar."""

    def __init__(self, prog: str) -> None:
        super().__init__(prog, width=_terminal_columns() - 2)  # argparse's own margin


def _terminal_columns() -> int:
    """The width `shutil.get_terminal_size()` finds: $COLUMNS, else standard output's
    terminal, else 80."""
    try:
        return int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        pass
    try:
        return os.get_terminal_size(sys.__stdout__.fileno()).columns  # type: ignore[union-attr]
    except (AttributeError, ValueError, OSError):
        return 80


class _ShowVersion(argparse.Action):
    """`--version`, looked up only when asked: importlib.metadata costs milliseconds."""

    def __init__(self, option_strings: Sequence[str], dest: str, help: str) -> None:
        super().__init__(option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS,
                         nargs=0, help=help)

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: str | Sequence[Any] | None, option_string: str | None = None,
                 ) -> None:
        from importlib.metadata import version

        print(f"{parser.prog}, version {version('rl1')}")
        parser.exit()


def _at_least_one(text: str) -> int:
    """An argparse type: a whole number, at least 1."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number of at least 1, got {text!r}")
    return value


# Shared by the commands that report diagnostics.
REPORT_OPTIONS = (
    argument("--format", dest="output_format", choices=FORMATS, default="human",
             help="human: text for people; json or sarif: for tools (default: %(default)s)"),
    argument("--color", choices=COLOR_CHOICES, default="auto",
             help="colour the human format; auto: only on a terminal, and not if NO_COLOR "
                  "is set (default: %(default)s)"),
)


# Inputs and outputs ---------------------------------------------------------------------


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
    stream = sys.stderr if err else sys.stdout
    colored = output_format == "human" and use_color(color, stream)
    stream.write(report(files, output_format, color=colored, action=action))
    return exit_status(files)


def write_stdout_bytes(data: bytes) -> None:
    sys.stdout.flush()  # what was printed as text comes first
    sys.stdout.buffer.write(data)
    sys.stdout.buffer.flush()


def write_file(target: str, data: bytes) -> None:
    """Writes `target` atomically; a Failure (exit status 2) saying why it cannot be."""
    from rl1.compiler.files import write_atomically

    try:
        write_atomically(target, data)
    except OSError as error:
        raise Failure(f"error: cannot write `{target}`: {error.strerror or error}") from None


MAX_ILC_BYTES = 16 * 1024 * 1024  # far more than any .ilc file holds


def read_ilc(file: str) -> bytes:
    """The bytes of an .ilc file; a Failure with exit status 2 when it cannot be read, 1
    when it is too large to be one (without reading a huge file whole)."""
    try:
        with open(file, "rb") as stream:
            data = stream.read(MAX_ILC_BYTES + 1)
    except OSError as error:
        raise Failure(f"error: cannot read `{file}`: {error.strerror or error}") from None
    if len(data) > MAX_ILC_BYTES:
        raise Failure(f"error: `{file}` is larger than {MAX_ILC_BYTES} bytes: not an .ilc "
                      "file", EXIT_ERRORS)
    return data


# The commands -------------------------------------------------------------------------


@command("check", argument("files", nargs="+", metavar="FILE",
                           help="an RL/I program; `-` is standard input"),
         *REPORT_OPTIONS)
def check(files: list[str], output_format: Format, color: ColorChoice) -> int:
    """Check RL/I programs and report every problem found.

    `-` reads standard input. Exit status: 0 no errors (warnings allowed), 1 errors,
    2 an unreadable file."""
    from rl1.compiler.analysis import analyze

    checked: list[FileDiagnostics] = []
    for name in files:
        source = read_input(name)
        if isinstance(source, Source):
            checked.append(FileDiagnostics(source.name, source.text,
                                           analyze(source.text).diagnostics))
        else:
            checked.append(source)
    return emit(checked, output_format, color, "check")


@command(
    "compile",
    argument("file", metavar="FILE", help="the RL/I program; `-` is standard input"),
    argument("-o", "--output", metavar="PATH",
             help="where to write; `-` is standard output. Default: FILE.ilc beside the "
                  "source (standard output with --emit ir)"),
    argument("-s", "--strip", action="store_true",
             help="leave out the debug section (the map from code to source lines)"),
    argument("--emit", dest="emit_kind", choices=EMIT_CHOICES, default="ilc",
             help="ilc: the .ilc file; ir: the IR as text (default: %(default)s)"),
    argument("-O", dest="optimize", default="0", metavar="LEVEL",
             help="optimization level; only -O0 (none) exists so far"),
    *REPORT_OPTIONS,
)
def compile_program(file: str, output: str | None, strip: bool, emit_kind: Emit,
                    optimize: str, output_format: Format, color: ColorChoice) -> int:
    """Compile an RL/I program: `rl1c FILE.rob -o FILE.ilc`.

    `-` reads standard input. Diagnostics go to standard error; nothing is written when
    the program has errors. Exit status: 0 compiled (warnings allowed), 1 errors,
    2 an unreadable input or an output that cannot be written."""
    from rl1.compiler.backend.driver import OPTIMIZATION_LEVELS, compile_text

    if optimize not in {str(level) for level in OPTIMIZATION_LEVELS}:
        raise UsageError(f"argument -O: `-O{optimize}`: only -O0 (no optimization) exists "
                         "so far")
    if strip and emit_kind == "ir":
        raise UsageError("--strip drops the debug section of an .ilc file; "
                         "it has no meaning with --emit ir")
    target = output or ("-" if emit_kind == "ir" else _default_output(file))
    source = read_input(file)
    if not isinstance(source, Source):
        return emit([source], output_format, color, "compile", err=True)
    if target != "-" and file != "-" and os.path.exists(target) \
            and os.path.samefile(file, target):
        raise UsageError(f"the output `{target}` is the source file itself: "
                         "give another path with -o")
    compilation = compile_text(source.text, os.path.basename(source.name), emit=emit_kind,
                               strip_debug=strip)
    status = emit([FileDiagnostics(source.name, source.text, compilation.diagnostics)],
                  output_format, color, "compile", err=True)
    if compilation.output is None:
        return status
    if target != "-":
        write_file(target, compilation.output)
    elif emit_kind == "ilc" and sys.stdout.isatty():
        raise UsageError("an .ilc file is binary and standard output is a "
                         "terminal: redirect it, or give -o FILE.ilc")
    else:
        write_stdout_bytes(compilation.output)
    return status


def _default_output(source: str) -> str:
    if source == "-":
        raise UsageError("reading standard input there is no file name to name the "
                         "output after: give -o FILE.ilc (or -o - for standard output)")
    return _with_suffix(source, ".ilc")


def _with_suffix(path: str, suffix: str) -> str:
    """`path` with its extension replaced by `suffix` (pathlib, 3 ms to import, is kept
    off the check path)."""
    return os.path.splitext(path)[0] + suffix


@command(
    "explain",
    argument("code", nargs="?", metavar="CODE", help="a diagnostic code, such as E0101"),
    argument("--list", dest="list_codes", action="store_true",
             help="list every code with its title"),
)
def explain(code: str | None, list_codes: bool) -> int:
    """Explain a diagnostic code in depth, with examples: `rl1c explain E0101`."""
    from rl1.compiler.reporting.catalogue import CODES

    if list_codes == (code is not None):
        raise UsageError("give a code, as in `rl1c explain E0101`, or --list")
    if code is None:
        for entry in CODES.values():
            print(f"{entry.code}  {entry.title}")
        return 0
    info = CODES.get(code.strip().upper())
    if info is None:
        raise Failure(f"error: `{code}` is not a diagnostic code of rl1c\n"
                      "  = help: `rl1c explain --list` lists every code with its title")
    sys.stdout.write(info.explanation())
    return 0


@command("dis", argument("file", metavar="FILE", help="the .ilc file"))
def dis(file: str) -> int:
    """Disassemble an .ilc file into .ils text on standard output.

    The program's source lines are shown when its source file is found (beside the .ilc,
    or by the recorded name). Exit status: 0 done, 1 the file is not valid intermediate
    code, 2 an unreadable file."""
    from rl1.compiler.ils.disasm import disassemble, source_beside
    from rl1.vm.verifier import VerifyError

    data = read_ilc(file)
    try:
        text = disassemble(data, file, source_beside(file))
    except VerifyError as error:
        raise Failure(f"error: {file}: byte {error.offset}: {error.message}",
                      EXIT_ERRORS) from None
    sys.stdout.write(text)
    return 0


@command(
    "asm",
    argument("file", metavar="FILE", help="the .ils file"),
    argument("-o", "--output", metavar="PATH",
             help="where to write the .ilc file; `-` is standard output. "
                  "Default: FILE.ilc beside the .ils file"),
)
def assemble_file(file: str, output: str | None) -> int:
    """Assemble .ils text (as `rl1c dis` prints it) into an .ilc file.

    The result must pass the verifier. Exit status: 0 written, 1 errors in the text
    (nothing is written), 2 an unreadable input or an output that cannot be written."""
    from rl1.compiler.ils.asm import AsmError, assemble

    try:
        source = read_source(file)
    except SourceError as error:
        raise Failure(f"error: {error}") from None
    target = output or _with_suffix(file, ".ilc")
    if target != "-" and os.path.exists(target) and os.path.samefile(file, target):
        raise UsageError(f"the output `{target}` is the input file itself: "
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
        write_file(target, data)
    return 0


@command(
    "fmt",
    argument("files", nargs="+", metavar="FILE",
             help="an RL/I program; `-` is standard input"),
    argument("--check", action="store_true",
             help="change nothing; list the files formatting would change (exit status 1)"),
    argument("--diff", action="store_true",
             help="change nothing; print what formatting would change as a unified diff"),
)
def fmt(files: list[str], check: bool, diff: bool) -> int:
    """Put RL/I programs in the canonical layout (spec/language.md, section 11).

    Each file is rewritten in place in its own encoding; `-` formats standard input to
    standard output. Exit status: 0 done, 1 (--check) a file would change, 2 a file cannot
    be read or written."""
    from rl1.compiler import formatter

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
            sys.stdout.write(formatter.unified_diff(source.name, source.text, formatted))
        if check and changed:
            print(source.name)
            status = max(status, EXIT_ERRORS)
        if check or diff:
            continue
        if name == "-":
            write_stdout_bytes(formatter.encode_like(source, formatted, bom=False))
        elif changed:
            try:
                formatter.rewrite(source, formatted)
            except OSError as error:
                print(f"error: cannot write `{name}`: {error.strerror or error}",
                      file=sys.stderr)
                status = EXIT_USAGE
    return status


@command(
    "run",
    argument("file", metavar="FILE", help="an RL/I program (.rob) or a compiled .ilc file"),
    argument("--sensors", metavar="FILE",
             help="sensor script for the scripted device (JSON, or TOML if FILE ends in "
                  ".toml). Without one every sensor reads 0 and the line is never lost"),
    argument("--format", dest="run_format", choices=("text", "json"), default="text",
             help="text: for people; json: one object for tools (default: %(default)s)"),
    argument("--budget", type=_at_least_one, default=DEFAULT_BUDGET, metavar="N",
             help="instructions (statements with --engine ast) before the watchdog stops "
                  "a runaway program (default: %(default)s)"),
    argument("--engine", choices=ENGINE_CHOICES, default="vm",
             help="vm: compile, then run on the reference VM; ast: interpret the source "
                  "(default: %(default)s)"),
)
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
            raise UsageError("--engine ast interprets RL/I source; an .ilc file runs "
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
