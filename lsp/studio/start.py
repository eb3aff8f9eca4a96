"""Starting the studio for a folder: the command line's files checked, the address
printed and opened, then served until Ctrl-C."""

from __future__ import annotations

import asyncio
import sys
import webbrowser
from pathlib import Path
from typing import TextIO

from .connection import Studio
from .files import Folder, Refused
from .server import HOST, Gate, Server, new_token, serve_studio


class CannotStart(Exception):
    """The studio cannot serve: the message says why and what to do."""


def studio_for(folder: str | Path, program: str | None, world: str | None) -> Studio:
    """The setting for FOLDER and the command line's FILE.rob and --world FILE (by
    default FILE's name with .world.toml in place of .rob, when that file exists)."""
    root = Folder(folder)
    if program is not None and not program.endswith(".rob"):
        raise CannotStart(f"{program}: the studio opens an RL/I program, a .rob file")
    if world is None and program is not None:
        paired = program.removesuffix(".rob") + ".world.toml"
        world = paired if Path(folder, paired).is_file() else None
    return Studio(root, _inside(root, folder, program), _inside(root, folder, world))


def _inside(root: Folder, folder: str | Path, path: str | None) -> str | None:
    """`path` (relative to `folder`) as the protocol names it, relative to the root."""
    if path is None:
        return None
    try:
        return root.relative(root.resolve(str(Path(folder, path))))
    except Refused as refused:
        raise CannotStart(str(refused)) from None


def serve(studio: Studio, port: int, open_browser: bool, out: TextIO = sys.stdout) -> None:
    """Serve `studio` on 127.0.0.1:`port` (0: a free one) until interrupted; CannotStart
    when the port cannot be had, and the OSError of `out` when the address, which only
    it shows, cannot be written there (a closed or full standard output)."""
    token = new_token()
    server = Server(Gate(token), studio)

    def listening(port: int) -> None:
        address = f"http://{HOST}:{port}/?token={token}"
        try:
            print(f"rl1c studio: serving {studio.folder.root} at {address} (Ctrl-C stops "
                  "it)", file=out, flush=True)
        except OSError as error:
            raise _Unshown(error) from None
        if open_browser:
            webbrowser.open(address)

    try:
        asyncio.run(serve_studio(server, port, listening))
    except _Unshown as unshown:
        raise unshown.error from None  # rl1c's Command says it, as any output's failure
    except OSError as error:
        raise CannotStart(f"cannot listen on {HOST}:{port}: {error.strerror or error}; "
                          "choose another port with --port, or 0 for any free one") from None


class _Unshown(Exception):
    """The address could not be written: `error`, kept apart from the listening's."""

    def __init__(self, error: OSError) -> None:
        super().__init__(str(error))
        self.error = error
