"""The commands on RL/I source: `rl1c check`, `rl1c fmt` and `rl1c explain`.

Each command imports the stage it runs when it runs, so that no command loads what only
another one needs (`rl1c explain` no checker, `rl1c check` no formatter).
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import click

from rl1.compiler.frontend.source import Source
from rl1.compiler.reporting.catalogue import CODES
from rl1.compiler.reporting.render import (
    EXIT_ERRORS,
    EXIT_USAGE,
    ColorChoice,
    FileDiagnostics,
    Format,
)

from .command import PATH, Command, Failure, color_option, force_option, format_option
from .streams import emit, read_input, write_stdout_bytes

if TYPE_CHECKING:  # click's completion module loads only when a shell asks
    from click.shell_completion import CompletionItem

SECTION = "RL/I programs"


@click.command(cls=Command)
@click.argument("files", nargs=-1, required=True, metavar="FILE...", type=PATH)
@format_option
@color_option
def check(files: tuple[str, ...], output_format: Format, color: ColorChoice) -> int:
    """Check RL/I programs and report every problem found.

    FILE is an RL/I program; `-` reads standard input. Exit status: 0 no errors
    (warnings allowed), 1 errors, 2 an unreadable file."""
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


@click.command(cls=Command)
@click.argument("files", nargs=-1, required=True, metavar="FILE...", type=PATH)
@click.option("--check", is_flag=True,
              help="change nothing; list the files formatting would change (exit status 1)")
@click.option("--diff", is_flag=True,
              help="change nothing; print what formatting would change as a unified diff")
@force_option
def fmt(files: tuple[str, ...], check: bool, diff: bool, force: bool) -> int:
    """Put RL/I programs in the canonical layout (spec/language.md, section 11).

    Each FILE is rewritten in place in its own encoding; `-` formats standard input to
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
                formatter.rewrite(source, formatted, force=force)
            except OSError as error:
                print(f"error: cannot write `{name}`: {error.strerror or error}",
                      file=sys.stderr)
                status = EXIT_USAGE
    return status


def _complete_code(ctx: click.Context, param: click.Parameter,
                   incomplete: str) -> list[CompletionItem]:
    """The diagnostic codes starting with what is typed, each with its title."""
    from click.shell_completion import CompletionItem

    prefix = incomplete.strip().upper()
    return [CompletionItem(code, help=info.title) for code, info in CODES.items()
            if code.startswith(prefix)]


@click.command(cls=Command)
@click.argument("code", required=False, metavar="[CODE]", shell_complete=_complete_code)
@click.option("--list", "list_codes", is_flag=True, help="list every code with its title")
def explain(code: str | None, list_codes: bool) -> int:
    """Explain a diagnostic code in depth, with examples: `rl1c explain E0101`."""
    if list_codes == (code is not None):
        raise click.UsageError("give a code, as in `rl1c explain E0101`, or --list")
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


COMMANDS = (check, fmt, explain)
