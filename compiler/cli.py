"""`rl1c`: compile RL/I (`rl1c FILE.rob -o FILE.ilc`) and the actions beside it.

Each action is a thin wrapper: parse options, call the stage that does the work, map the
outcome to an exit status. Exit statuses: 0 success, 1 the input has errors,
2 a usage problem or an unreadable file.
"""

from __future__ import annotations

import sys

import click

from .frontend import analyze
from .source import SourceError, read_source

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2


class _CompileByDefault(click.Group):
    """Treats `rl1c FILE ...` as `rl1c compile FILE ...`, so compiling needs no verb."""

    def resolve_command(
        self, ctx: click.Context, args: list[str]
    ) -> tuple[str | None, click.Command | None, list[str]]:
        if args and args[0] not in self.commands and not args[0].startswith("-"):
            args = ["compile", *args]
        return super().resolve_command(ctx, args)


@click.group(cls=_CompileByDefault, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="rl1", prog_name="rl1c")
def main() -> None:
    """The RL/I toolchain. `rl1c FILE.rob -o FILE.ilc` compiles; the commands below
    check, format, explain, disassemble, assemble and run programs."""


@main.command()
@click.argument("files", nargs=-1, required=True)
def check(files: tuple[str, ...]) -> None:
    """Check RL/I programs and report every problem found."""
    status = EXIT_OK
    for name in files:
        try:
            source = read_source(name)
        except SourceError as error:
            click.echo(f"error[E0100]: {error}", err=True)
            status = EXIT_USAGE
            continue
        analysis = analyze(source.text)
        for d in analysis.diagnostics:
            click.echo(f"{name}:{d.span.line}:{d.span.column}: "
                       f"{d.severity.value}[{d.code}]: {d.message}")
        if analysis.has_errors and status == EXIT_OK:
            status = EXIT_ERRORS
    sys.exit(status)
