"""rl1.toml, the project file: the options of `rl1c check` that a team shares, read from
the nearest rl1.toml in the checked file's folder or above it.

    [check]
    select = ["W"]             # report only these warnings (codes or prefixes)
    ignore = ["W0603"]         # never these
    warnings-as-errors = true  # for CI: a warning fails the check

Every failure is a ProjectFileError whose message names the file, the place and what to
do; a key this version does not know is refused rather than silently ignored.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

from rl1.compiler.files import SourceError, read_bounded

from .selection import Selection, SelectionError, parse_codes

PROJECT_FILE = "rl1.toml"
MAX_PROJECT_FILE_BYTES = 1024 * 1024
TABLE = "check"


class ProjectFileError(Exception):
    """An rl1.toml that cannot be read (`unreadable`) or used: its `path`, and where in
    it and why (`detail`); str() is "PATH: DETAIL"."""

    def __init__(self, path: str, detail: str, *, unreadable: bool = False,
                 help: str = "") -> None:
        super().__init__(f"{path}: {detail}")
        self.path = path
        self.detail = detail
        self.unreadable = unreadable
        self.help = help


def find_project_file(folder: str) -> str | None:
    """The nearest rl1.toml in `folder` or a folder above it."""
    here = os.path.abspath(folder)
    while True:
        path = os.path.join(here, PROJECT_FILE)
        if os.path.isfile(path):
            return path
        parent = os.path.dirname(here)
        if parent == here:
            return None
        here = parent


def load_project_file(path: str) -> Selection:
    """The selection an rl1.toml sets (what it leaves out stays unset)."""
    import tomllib  # only when a project has the file

    try:
        data = read_bounded(path, MAX_PROJECT_FILE_BYTES, "a project file")
        document = tomllib.loads(data.decode("utf-8"))
    except SourceError as error:
        raise ProjectFileError(error.path, error.reason, unreadable=True,
                               help=error.help) from None
    except UnicodeDecodeError as error:
        raise ProjectFileError(path, f"not UTF-8 text (byte {error.start}); TOML files are "
                               "UTF-8") from None
    except tomllib.TOMLDecodeError as error:
        raise ProjectFileError(path, f"not valid TOML: {error}") from None
    except RecursionError:  # tomllib reads nested arrays recursively
        raise ProjectFileError(path, "arrays or tables nested too deeply to read") from None
    unknown = sorted(set(document) - {TABLE})
    if unknown:
        raise ProjectFileError(path, f"unknown table or key `{unknown[0]}`: rl1.toml has "
                               f"a `[{TABLE}]` table only")
    table = document.get(TABLE, {})
    if not isinstance(table, dict):
        raise ProjectFileError(path, f"`{TABLE}` must be a table, `[{TABLE}]`")
    return _selection(path, table)


_KEYS = ("select", "ignore", "warnings-as-errors")


def _selection(path: str, table: dict[str, Any]) -> Selection:
    for key in table:
        if key not in _KEYS:
            raise ProjectFileError(path, f"unknown key `{key}` in `[{TABLE}]`; the keys are "
                                   + ", ".join(f"`{known}`" for known in _KEYS))

    def codes(key: str) -> tuple[str, ...] | None:
        value = table.get(key)
        if value is None:
            return None
        if not isinstance(value, list) or not all(isinstance(item, str) for item in value):
            raise ProjectFileError(path, f"`{key}` in `[{TABLE}]` must be a list of codes, "
                                   f'such as {key} = ["W0601", "W06"]')
        try:
            return parse_codes(value)
        except SelectionError as error:
            raise ProjectFileError(path, f"`{key}` in `[{TABLE}]`: {error}") from None

    strict = table.get("warnings-as-errors")
    if strict is not None and not isinstance(strict, bool):
        raise ProjectFileError(path, f"`warnings-as-errors` in `[{TABLE}]` must be true or "
                               "false")
    return Selection(codes("select"), codes("ignore"), strict)


def project_selection() -> Callable[[str], Selection]:
    """A lookup of the selection rl1.toml sets for a file (`-`: standard input, whose
    project is the working directory's), each folder searched and each file read once."""
    by_folder: dict[str, str | None] = {}
    by_file: dict[str, Selection] = {}

    def lookup(name: str) -> Selection:
        folder = os.path.dirname(os.path.abspath(name)) if name != "-" else os.getcwd()
        if folder not in by_folder:
            by_folder[folder] = find_project_file(folder)
        path = by_folder[folder]
        if path is None:
            return Selection()
        if path not in by_file:
            by_file[path] = load_project_file(path)
        return by_file[path]

    return lookup
