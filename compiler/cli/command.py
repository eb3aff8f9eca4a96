"""What every `rl1c` command shares: the click command class that turns what a command
returns or raises into the exit status, the parameter types with their messages, and the
options of the commands that report diagnostics.

A command is a function returning its exit status, decorated `@click.command(cls=Command)`
with its parameters; its docstring is its help, the first line its summary in
`rl1c --help`. It ends early by raising `CommandError` (what is wrong and a status,
said as `rl1c run: error: ...`), `Failure` (a message for standard error, such as a
file's E0100 diagnostic, and a status) or `click.UsageError` (shown with the command's
usage, status 2).
"""

from __future__ import annotations

import contextlib
import errno
import os
import signal
import sys
from collections.abc import Callable, Iterator, Sequence
from types import FrameType
from typing import TYPE_CHECKING, Any, Literal, TypeVar

import click

from rl1.compiler.reporting.render import COLOR_CHOICES, EXIT_ERRORS, EXIT_USAGE, FORMATS
from rl1.vm.defaults import DEFAULT_BUDGET, ENGINES

if TYPE_CHECKING:  # click's completion module loads only when a shell asks
    from click.shell_completion import CompletionItem

EXIT_INTERNAL = 3
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report a program stopped by Ctrl-C

CONTEXT_SETTINGS: dict[str, Any] = {"help_option_names": ["-h", "--help"]}

F = TypeVar("F", bound=Callable[..., Any])


class Failure(Exception):
    """Ends a command: `message` goes to standard error, `status` is the exit status."""

    def __init__(self, message: str, status: int = EXIT_USAGE) -> None:
        super().__init__(message)
        self.status = status


class CommandError(Failure):
    """A Failure that is no diagnostic of a file (those are `error[E0100]`, a Failure's
    whole message): `message` is said as every command's errors are, its usage errors
    too, `rl1c reduce: error: MESSAGE` (`message_line`)."""


MessageKind = Literal["error", "warning", "note"]


def message_line(command_path: str, kind: MessageKind, message: str) -> str:
    """A message of the command `command_path` (`rl1c sim`) that is no file's diagnostic:
    `rl1c sim: warning: message`. Errors, warnings and notes alike name the command that
    says them, as its usage errors do; `rl1c` alone when no command runs (the plugins'
    entry points), and `rl1-lsp` or `rl1-dap` for those programs' command lines."""
    return f"{command_path}: {kind}: {message}"


class Context(click.Context):
    """Makes the help as wide as the terminal ($COLUMNS, else the terminal's width, as
    shutil finds it): click would stop at 80 columns, and at exactly 80 under CliRunner."""

    def make_formatter(self) -> click.HelpFormatter:
        import shutil  # with bz2 and lzma, 2 ms of every start; only help needs it

        return click.HelpFormatter(width=max(shutil.get_terminal_size().columns - 2, 50))


def write_usage(command: click.Command, ctx: click.Context,
                formatter: click.HelpFormatter) -> None:
    """The usage line as `usage: rl1c check [OPTIONS] FILE...`, lower case as in the
    error messages that follow it."""
    formatter.write_usage(ctx.command_path, " ".join(command.collect_usage_pieces(ctx)),
                          prefix="usage: ")


class ToolCommand(click.Command):
    """A click command whose help and usage read as rl1c's (`-h`, `usage: ...`, as wide
    as the terminal): rl1c's commands, and the command lines of rl1-lsp and rl1-dap."""

    context_class = Context

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("context_settings", CONTEXT_SETTINGS)
        super().__init__(*args, **kwargs)

    def format_usage(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        write_usage(self, ctx, formatter)


class Command(ToolCommand):
    """An `rl1c` command: its callback returns the exit status. Failures, a closed
    output pipe, Ctrl-C and bugs become a message on standard error and a status here,
    before click's own handling (which would print a blank line on Ctrl-C)."""

    def invoke(self, ctx: click.Context) -> int:
        try:
            status: int = super().invoke(ctx)
            sys.stdout.flush()  # a closed pipe shows here, not when the process exits
            return status
        except (click.ClickException, click.exceptions.Exit):
            raise  # usage errors are shown by the group, with the usage
        except CommandError as failure:
            print(message_line(ctx.command_path, "error", str(failure)), file=sys.stderr)
            return failure.status
        except Failure as failure:
            print(failure, file=sys.stderr)
            return failure.status
        except OSError as error:
            if error.filename is not None:  # a file a command forgot to guard: a bug
                return internal_error(error)
            return output_failed(error)
        except KeyboardInterrupt:
            return interrupted()
        except Exception as error:
            return internal_error(error)


def command_line_status(run: Callable[[], object], prog: str) -> int:
    """The exit status of `run`, a click command line run not standalone (its `main`
    with `standalone_mode=False`), saying what ends it early as rl1c says it: a usage
    error as `usage: ...` then `rl1c check: error: what is wrong` (status 2), another of
    click's errors as `PROG: error: ...` with its status (`prog`: the program's name),
    Ctrl-C that click turned into Abort as `PROG: interrupted` (130)."""
    try:
        status = run()
    except click.UsageError as error:
        return show_usage_error(error, prog)
    except click.ClickException as error:
        print(message_line(prog, "error", error.format_message()), file=sys.stderr)
        return error.exit_code
    except click.Abort:
        return interrupted(prog)
    return status if isinstance(status, int) else 0  # a callback that returns nothing


def show_usage_error(error: click.UsageError, prog: str) -> int:
    """Prints the usage and what is wrong, as `rl1c check: error: ...` (`prog` when the
    error names no command); exit status 2."""
    ctx = error.ctx
    if ctx is not None:
        click.echo(ctx.get_usage(), err=True)
    said = message_line(ctx.command_path if ctx is not None else prog, "error",
                        describe(error))
    click.echo(said, err=True)
    return EXIT_USAGE


def describe(error: click.UsageError) -> str:
    """What is wrong, in the words rl1c has always used."""
    if isinstance(error, click.MissingParameter) and isinstance(error.param, click.Argument):
        return f"the following arguments are required: {error.param.human_readable_name}"
    if isinstance(error, click.BadParameter) and error.param is not None:
        return f"argument {'/'.join(error.param.opts)}: {error.message}"
    if isinstance(error, click.NoSuchOption):
        close = f" (did you mean {error.possibilities[0]}?)" if error.possibilities else ""
        return f"unrecognized arguments: {error.option_name}{close}"
    return error.format_message()


def output_failed(error: OSError) -> int:
    """Standard output could not be written. A closed pipe (`rl1c dis x.ilc | head`) ends
    quietly with status 1; anything else (a full disk, a closed descriptor) is said in
    one line, status 2. What is left in the buffer goes to /dev/null, or Python would
    fail again flushing it at exit."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    if isinstance(error, BrokenPipeError):
        return EXIT_ERRORS
    if error.errno == errno.EBADF:  # main.py holds a closed standard output so
        problem = ("standard output is closed; send it to a file, a pipe or /dev/null "
                   "(`> FILE`, not `>&-`)")
    else:
        problem = f"{error.strerror or error}; free some space or write elsewhere"
    with contextlib.suppress(OSError):  # standard error may be just as full
        print(message_line("rl1c", "error", f"cannot write the output: {problem}"),
              file=sys.stderr)
    return EXIT_USAGE


def interrupted(prog: str = "rl1c") -> int:
    print(f"{prog}: interrupted", file=sys.stderr)
    return EXIT_INTERRUPTED


# What stops a campaign (rl1c fuzz, rl1c sim --runs), which then keeps its summary:
# Ctrl-C, and the SIGTERM of a CI job's timeout or of kill.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def stop_signals_handled(handler: Callable[[int, FrameType | None], None]
                         ) -> Iterator[None]:
    """While inside, SIGINT and SIGTERM call `handler` instead of ending rl1c; the
    handlers before are back after."""
    previous = {signum: signal.signal(signum, handler) for signum in STOP_SIGNALS}
    try:
        yield
    finally:
        for signum, earlier in previous.items():
            signal.signal(signum, earlier)


def internal_error(error: Exception) -> int:
    """Reports a bug in rl1c; its exit status (3)."""
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


# Parameter types ----------------------------------------------------------------------


def choice_option(*names: str, choices: Sequence[str], help: str,
                  **settings: Any) -> Callable[[F], F]:
    """An option taking one of `choices`, shown as `--format {human,json,sarif}`, with
    the message `invalid choice: 'xml' (choose from human, json, sarif)`; the choices
    complete in the shell."""
    def one_of(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
        if value is None:  # not given, and the default is to decide later
            return None
        if value not in choices:
            raise click.BadParameter(
                f"invalid choice: {value!r} (choose from {', '.join(choices)})", ctx, param)
        return value

    def complete(ctx: click.Context, param: click.Parameter,
                 incomplete: str) -> list[CompletionItem]:
        from click.shell_completion import CompletionItem

        return [CompletionItem(choice) for choice in choices if choice.startswith(incomplete)]

    return click.option(*names, callback=one_of, shell_complete=complete,
                        metavar="{" + ",".join(choices) + "}", show_default=True, help=help,
                        **settings)


def at_least_one(ctx: click.Context, param: click.Parameter, value: str) -> int:
    """An option's callback: a whole number, at least 1."""
    return _whole_number(ctx, param, value, "of at least 1")


def a_budget(ctx: click.Context, param: click.Parameter, value: str) -> int:
    """An option's callback: a watchdog budget, a whole number in 1..MAX_BUDGET."""
    from rl1.vm.faults import MAX_BUDGET  # the VM's modules load only for commands that run

    return _whole_number(ctx, param, value, f"from 1 to {MAX_BUDGET}", most=MAX_BUDGET)


def _whole_number(ctx: click.Context, param: click.Parameter, value: str, expected: str,
                  most: int | None = None) -> int:
    """`value` as a whole number from 1 to `most` (no bound when None), or the option's
    usage error saying it expected a whole number `expected`."""
    try:
        number = int(value)
    except ValueError:
        number = 0
    if number < 1 or (most is not None and number > most):
        raise click.BadParameter(f"expected a whole number {expected}, got {value!r}",
                                 ctx, param)
    return number


OptionCallback = Callable[[click.Context, click.Parameter, str], int]


def or_none(callback: OptionCallback
            ) -> Callable[[click.Context, click.Parameter, str | None], int | None]:
    """`callback` for an option that may be left out: left out (None), it stays None."""

    def left_out_or(ctx: click.Context, param: click.Parameter, value: str | None
                    ) -> int | None:
        return None if value is None else callback(ctx, param, value)

    return left_out_or


def completable(word: str) -> bool:
    """Whether the shell's word `word` can be completed: click writes completions as
    UTF-8, which a word holding bytes that are not UTF-8 (a Latin-1 file name, held as
    surrogate escapes) has no form in, and it failed writing it back."""
    try:
        word.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


class _Path(click.Path):
    def shell_complete(self, ctx: click.Context, param: click.Parameter,
                       incomplete: str) -> list[CompletionItem]:
        return super().shell_complete(ctx, param, incomplete) if completable(incomplete) \
            else []


# A path as given: the stages read it and report what is wrong in their own terms (E0100
# for a source file), so click checks nothing; it completes file names in the shell.
PATH = _Path(readable=False, allow_dash=True)

# Shared by the commands that report diagnostics.
format_option = choice_option(
    "--format", "output_format", choices=FORMATS, default="human",
    help="human: text for people; concise: one line a problem, file:line:col: "
         "warning[CODE]: message (for problem matchers and grep); json or sarif: for tools")
color_option = choice_option(
    "--color", choices=COLOR_CHOICES, default="auto",
    help="colour the human format; auto: only on a terminal, and not if NO_COLOR is set "
         "or TERM is dumb")


force_option = click.option(
    "--force", is_flag=True,
    help="replace an output file even when it is read-only (a device or a FIFO is "
         "written to, never replaced)")

# Shared by the commands that run a program (rl1c run, rl1c sim).
engine_option = choice_option(
    "--engine", choices=ENGINES, default="vm",
    help="vm: compile, then run on the reference VM; ast: interpret the source; c: run on "
         "the C VM of the firmware (vm/c, built on first use)")
budget_option = click.option(
    "--budget", type=str, default=str(DEFAULT_BUDGET), callback=a_budget, metavar="N",
    show_default=True,
    help="instructions (statements with --engine ast) before the watchdog stops a runaway "
         "program")
