"""`rl1c`: compile RL/I (`rl1c FILE.rob -o FILE.ilc`) and the commands beside it.

The commands live by what they work on: source.py (check, fmt, explain), build.py
(compile, run, dis, asm), sim.py (sim), testing.py (test), new.py (new), fuzz.py
(fuzz), reduce.py (reduce) and docs.py (docs); command.py has what they share. Other
packages add commands through entry points (plugins.py): rl1.lsp adds `rl1c studio`.
A command's module is imported only when the command runs (or help lists them all), as
click's documentation shows for lazy groups: `rl1c check` pays for no other command.

This module makes them one click group with what the toolchain adds to click: a first
word that names a file means `compile`, a mistyped command gets a suggestion, and usage
errors read `usage: ...` then `rl1c check: error: what is wrong`. Exit statuses: 0
success, 1 the input has errors, 2 a usage problem or an unreadable file, 3 an internal
error (a bug in rl1c), 10-13 faults of `rl1c run`, 130 interrupted.

To add a command: write it in the module of its group (or a new one listed in
`MODULES`), add its name there, as command.py says.
"""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import Sequence
from types import ModuleType
from typing import Any

import click

from rl1.compiler.reporting.render import EXIT_USAGE

from . import plugins
from .command import (
    CONTEXT_SETTINGS,
    Context,
    command_line_status,
    completable,
    internal_error,
    output_failed,
    write_usage,
)

# The modules of the commands, in the order of `rl1c --help`'s sections, with the names
# of their commands (each module's SECTION and COMMANDS; a test holds the names equal).
MODULES: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("source", ("check", "fmt", "explain")),
    ("build", ("compile", "run", "dis", "asm")),
    ("sim", ("sim",)),
    ("testing", ("test",)),
    ("new", ("new",)),
    ("fuzz", ("fuzz",)),
    ("reduce", ("reduce",)),
    ("docs", ("docs",)),
)
COMMAND_NAMES = tuple(name for _, names in MODULES for name in names)


def plugin_names() -> tuple[str, ...]:
    """The commands of the plugins installed (plugins.py), but for any named as one of
    rl1c's own, which a plugin cannot replace."""
    return tuple(name for name in plugins.installed() if name not in COMMAND_NAMES)


def command_names() -> tuple[str, ...]:
    """Every command: rl1c's own, then the plugins'."""
    return (*COMMAND_NAMES, *plugin_names())


def command_module(name: str) -> ModuleType:
    return importlib.import_module(f"{__package__}.{name}")


class Toolchain(click.Group):
    """The `rl1c` group: click's, with the toolchain's default command, suggestions,
    help sections and error messages."""

    context_class = Context

    def format_usage(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        write_usage(self, ctx, formatter)

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(command_names())  # as click's own groups list them

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        for module, names in MODULES:
            if cmd_name in names:
                commands: Sequence[click.Command] = command_module(module).COMMANDS
                return next(command for command in commands if command.name == cmd_name)
        if cmd_name in plugin_names():
            return plugins.load(cmd_name).command
        return None

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        sections: dict[str, list[click.Command]] = {}  # in the order of MODULES, then plugins'
        for name, _ in MODULES:
            module = command_module(name)
            sections.setdefault(module.SECTION, []).extend(module.COMMANDS)
        for name in plugin_names():
            plugin = plugins.load(name)
            sections.setdefault(plugin.section, []).append(plugin.command)
        with formatter.section("Commands"):
            for index, (section, commands) in enumerate(sections.items()):
                if index:
                    formatter.write_paragraph()
                formatter.write_heading(section)
                with formatter.indentation():
                    # The whole first sentence: write_dl wraps it to the terminal's width.
                    formatter.write_dl([(command.name or "", command.get_short_help_str(1000))
                                        for command in commands])

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        if not args and not ctx.resilient_parsing:
            # Nothing to do is a usage problem: the help goes to standard error.
            click.echo(ctx.get_help(), err=True)
            ctx.exit(EXIT_USAGE)
        if args and args[0] not in COMMAND_NAMES and names_a_file(args[0]):
            args = ["compile", *args]  # compiling needs no command
        return super().parse_args(ctx, args)

    def resolve_command(self, ctx: click.Context, args: list[str]
                        ) -> tuple[str | None, click.Command | None, list[str]]:
        name = args[0]
        if not name.startswith("-") and not ctx.resilient_parsing \
                and name not in COMMAND_NAMES and name not in plugin_names():
            raise click.UsageError(self._no_such_command(name), ctx)
        return super().resolve_command(ctx, args)

    def _no_such_command(self, name: str) -> str:
        import difflib  # for this message only

        names = command_names()
        close = difflib.get_close_matches(name, names, n=1)
        if close:
            return f"No such command {name!r}. Did you mean {close[0]!r}?"
        return (f"No such command {name!r}. The commands are {', '.join(names)}; "
                "to compile a file, give its path (such as `rl1c prog.rob`)")

    def shell_complete(self, ctx: click.Context, incomplete: str) -> list[Any]:
        from click.shell_completion import CompletionItem

        # The commands, and the files `rl1c FILE.rob` compiles.
        files = [CompletionItem(incomplete, type="file")] if completable(incomplete) else []
        return [*super().shell_complete(ctx, incomplete), *files]

    def main(self, args: Sequence[str] | None = None, prog_name: str | None = None,
             complete_var: str | None = None, standalone_mode: bool = True,
             **extra: Any) -> Any:
        """Runs the command line `args` (default: the process's arguments); returns the
        exit status, or exits with it in standalone mode (the default)."""
        _hold_closed_standard_streams()
        _escape_unprintable_output()
        name = prog_name or self.name or "rl1c"  # not "-c" or "__main__.py", however started
        try:
            status = command_line_status(
                lambda: super(Toolchain, self).main(args, name, complete_var,
                                                    standalone_mode=False, **extra), name)
        except OSError as error:  # writing --help or --version failed
            status = output_failed(error) if error.filename is None else internal_error(error)
        except Exception as error:
            status = internal_error(error)
        if standalone_mode:
            sys.exit(status)
        return status


def names_a_file(word: str) -> bool:
    """Whether `word`, first on the command line and no command, is a file to compile
    rather than a mistyped command: `-` (standard input), a path with a directory or an
    extension, or an existing file that no plugin's command is named as (the plugins are
    looked for only then, not for `rl1c prog.rob`)."""
    if word.startswith("-"):
        return word == "-"
    return (os.sep in word or "/" in word or os.path.splitext(word)[1] != ""
            or (os.path.exists(word) and word not in plugin_names()))


def _hold_closed_standard_streams() -> None:
    # A standard stream the shell closed (`rl1c dis x.ilc >&-`), which Python leaves as
    # None, gets /dev/null's descriptor, so that no file rl1c opens takes its number (an
    # output file would receive the report). Standard input's is write-only and standard
    # output's read-only: using them fails (EBADF) as using a closed descriptor does,
    # and the command says so.
    for number, name, access in ((0, "stdin", os.O_WRONLY), (1, "stdout", os.O_RDONLY),
                                 (2, "stderr", os.O_WRONLY)):
        if getattr(sys, name) is None:
            descriptor = os.open(os.devnull, access)  # the lowest free number: this one
            if descriptor != number:
                os.dup2(descriptor, number)
                os.close(descriptor)
            stream = open(number, "r" if number == 0 else "w", closefd=False)  # noqa: SIM115
            setattr(sys, name, stream)  # open for the process's life, as Python's own


def _escape_unprintable_output() -> None:
    # A terminal that cannot show a character (a Japanese comment in a Latin-1 locale)
    # gets an escape for it instead of a failure.
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is not None:
            reconfigure(errors="backslashreplace")


# Where a newcomer goes next; `rl1c docs` prints each of them in an installed package too.
EPILOG = """Read next: a first program and world of your own (`rl1c docs tutorial`), every
command (`rl1c docs commands`), editors (`rl1c docs editors`), firmware (`rl1c docs
firmware`). `rl1c docs` lists the documents; `rl1c docs NAME` prints one, such as one
that a help text names (`rl1c docs spec/sensors.md`)."""


@click.group(cls=Toolchain, context_settings=CONTEXT_SETTINGS, epilog=EPILOG,
             subcommand_metavar="COMMAND [ARGS]... | FILE.rob [OPTIONS]")
@click.version_option(package_name="rl1", prog_name="rl1c")
def rl1c() -> None:
    """The RL/I toolchain. `rl1c FILE.rob -o FILE.ilc` compiles (the same as
    `rl1c compile FILE.rob -o FILE.ilc`); the commands below check, format, explain,
    disassemble, assemble and run programs. `rl1c COMMAND --help` tells more."""
