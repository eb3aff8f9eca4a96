"""Commands that other packages add to `rl1c`, each an entry point of the group
`rl1.commands` named as its command and naming its module, which has SECTION and
COMMANDS as the modules of main.MODULES do. rl1.lsp adds `rl1c studio` so
(pyproject.toml), since nothing of rl1.compiler imports rl1.lsp.

Entry points are read only when a command is not one of rl1c's own, and for help and
completion: `rl1c check` pays nothing for them. A plugin that cannot be loaded is still
listed, as a command that says why and what to do (exit status 2), never a traceback; a
package whose entry points cannot be read is left out, with a warning.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING

import click

from .command import Command, CommandError, message_line

if TYPE_CHECKING:  # importlib.metadata takes tens of milliseconds to load: when asked
    from importlib.metadata import Distribution, EntryPoint

GROUP = "rl1.commands"
UNLOADED = "Commands that cannot be loaded"  # the help's section of broken plugins


@dataclass(frozen=True, slots=True)
class Plugin:
    """A plugin's command and the section of `rl1c --help` that lists it."""

    section: str
    command: click.Command


@functools.cache
def installed() -> dict[str, EntryPoint]:
    """The plugins installed, by command name (the first of each name found on the
    path, as Python finds the first of two modules). A package whose metadata cannot be
    read is left out, with a warning."""
    from importlib.metadata import distributions

    found: dict[str, EntryPoint] = {}
    for distribution in distributions():
        try:
            entries = distribution.entry_points.select(group=GROUP)
        except Exception as error:  # a file of its metadata that is no entry point list
            click.echo(message_line(
                "rl1c", "warning", "cannot read the entry points (entry_points.txt) of "
                f"{_named(distribution)} ({type(error).__name__}: {error}), which may add "
                "commands to rl1c; they are left out: install that package again"), err=True)
            continue
        for entry in entries:
            found.setdefault(entry.name, entry)
    return found


def _named(distribution: Distribution) -> str:
    """The package `distribution` as a message names it: its name, and where it is."""
    where = distribution.locate_file("")
    try:
        return f"the package `{distribution.metadata['Name']}` in {where}"
    except Exception:  # its metadata unreadable too
        return f"a package in {where}"


@functools.cache
def load(name: str) -> Plugin:
    """The installed plugin `name`'s command, or a command saying why it cannot be had."""
    entry = installed()[name]
    try:
        module = entry.load()
    except Exception as error:  # whatever importing another package's module raises
        return _unloaded(entry, f"importing `{entry.value}` failed "
                                f"({type(error).__name__}: {error})")
    problem = _malformed(module, name)
    if problem is not None:
        return _unloaded(entry, f"`{entry.value}` {problem}")
    command = next(command for command in module.COMMANDS if command.name == name)
    return Plugin(module.SECTION, command)


def _malformed(module: object, name: str) -> str | None:
    """What keeps `module` from being the module of the command `name`, if anything."""
    if not isinstance(module, ModuleType):
        return "is not a module (name a module, without `:`)"
    section = getattr(module, "SECTION", None)
    commands = getattr(module, "COMMANDS", None)
    if not isinstance(section, str) or not isinstance(commands, tuple):
        return "has no SECTION (a string) and COMMANDS (a tuple of click commands)"
    if not any(isinstance(command, click.Command) and command.name == name
               for command in commands):
        return f"has no command named `{name}` in its COMMANDS"
    return None


def _unloaded(entry: EntryPoint, why: str) -> Plugin:
    """A command, in the place of the plugin `entry`, that fails with `why`, whatever its
    arguments (`--help` too)."""
    package = entry.dist.name if entry.dist is not None else "the package that adds it"
    message = (f"the command cannot be loaded: {why}\n"
               f"  = help: `rl1c {entry.name}` comes from {package} (its entry point "
               f"`{entry.name} = {entry.value}` in the group `{GROUP}`); install it again, "
               f"such as with `pip install --force-reinstall {package}`, or `pip install "
               "-e .` in its checkout")

    def fail() -> int:
        raise CommandError(message)

    command = Command(entry.name, callback=fail, add_help_option=False,
                      help=f"Cannot be loaded: {why}.",
                      context_settings={"ignore_unknown_options": True,
                                        "allow_extra_args": True})
    return Plugin(UNLOADED, command)
