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

from rl1.compiler.files import SourceError, read_bounded

from .selection import Selection, SelectionError, parse_codes

PROJECT_FILE = "rl1.toml"
MAX_PROJECT_FILE_BYTES = 1024 * 1024
TABLE = "check"


class ProjectFileError(Exception):
    """An rl1.toml that cannot be read (`unreadable`) or used: its `path`, and why
    (`detail`); str() is "PATH: DETAIL", or `placed`, the place and why of a file read
    but not valid in the form of every configuration file's (vm.config.ConfigError's:
    "PATH:3: check.ignore: ...")."""

    def __init__(self, path: str, detail: str, *, unreadable: bool = False,
                 help: str = "", placed: str | None = None) -> None:
        super().__init__(placed or f"{path}: {detail}")
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
    # Only when a project has the file: the validation layer loads msgspec.
    from msgspec import UnsetType

    from rl1.vm.config import ConfigError, convert, error_at, read_document

    from .project_schema import ProjectFile

    try:
        data = read_bounded(path, MAX_PROJECT_FILE_BYTES, "a project file")
    except SourceError as error:
        raise ProjectFileError(error.path, error.reason, unreadable=True,
                               help=error.help) from None
    try:
        document, text = read_document(data, path, "toml")
        check = convert(document, ProjectFile, path, text).check
        codes: dict[str, tuple[str, ...] | None] = {}
        for key, value in (("select", check.select), ("ignore", check.ignore)):
            try:
                codes[key] = None if isinstance(value, UnsetType) else parse_codes(value)
            except SelectionError as error:
                raise error_at(path, text, (TABLE, key), str(error)) from None
    except ConfigError as error:
        raise ProjectFileError(path, error.detail, placed=str(error)) from error
    strict = None if isinstance(check.warnings_as_errors, UnsetType) else check.warnings_as_errors
    return Selection(codes["select"], codes["ignore"], strict)


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
