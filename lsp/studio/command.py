"""`rl1c studio`: the studio's page for the current folder (spec/studio.md), served by
rl1.lsp.studio, which needs the `websockets` package (the `ws` extra).

rl1c finds it through the entry point `studio` of the group `rl1.commands`
(pyproject.toml; compiler/cli/plugins.py), since rl1.compiler imports nothing of
rl1.lsp; like rl1c's own commands, it is an `rl1.compiler.cli.command.Command`."""

from __future__ import annotations

import os

import click

from rl1.compiler.cli.command import PATH, Command, CommandError

SECTION = "Studio"


@click.command(cls=Command)
@click.argument("file", metavar="[FILE.rob]", type=PATH, required=False)
@click.option("--world", metavar="FILE", type=PATH,
              help="the world to run in (default: FILE's name with .world.toml in place "
                   "of .rob, when there is one)")
@click.option("--port", type=click.IntRange(0, 65535), default=0, show_default=True,
              help="the port on 127.0.0.1 to serve on; 0: any free one")
@click.option("--no-browser", is_flag=True, help="print the address, do not open it")
def studio(file: str | None, world: str | None, port: int, no_browser: bool) -> int:
    """Write, run, watch and step a program in one page in the browser.

    Serves the page on 127.0.0.1 for the current folder (no file outside it is read or
    written), prints its address with its token, and opens it: an editor with the
    language server's help, the world with the vehicle moving as the program runs, the
    debugger (breakpoints, stepping, the variables, the trace) and the built-ins'
    palette. Ctrl-C stops it (exit status 130)."""
    try:
        import websockets  # noqa: F401
    except ImportError:
        raise CommandError("the studio needs the websockets package: "
                           "pip install 'rl1[ws]'") from None
    from .start import CannotStart, serve, studio_for

    try:
        serve(studio_for(os.getcwd(), file, world), port, open_browser=not no_browser)
    except CannotStart as error:
        raise CommandError(str(error)) from None
    return 0


COMMANDS = (studio,)
