"""The one folder the studio reads and writes (spec/studio.md, "Files").

A path from the page is used only when it has no `..`, is inside the folder with every
symbolic link resolved, and names a regular file (or, to save, a new file in a folder
inside). Files are opened without blocking, so that a FIFO swapped in after the check
does not hang the server, and checked again once open. Only the studio's kinds of file
are written.
"""

from __future__ import annotations

import hashlib
import os
import stat
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Literal

from rl1.compiler.files import write_atomically
from rl1.vm.config import excerpt

Kind = Literal["program", "world", "sensors"]
KINDS: dict[str, Kind] = {".rob": "program", ".world.toml": "world",
                          ".sensors.json": "sensors", ".sensors.toml": "sensors"}
"""The files the studio lists and writes, by how their names end."""

MAX_FILE_BYTES = 8 * 2**20
MAX_PATH = 4096  # Linux's PATH_MAX: no longer path names a file
MAX_LISTED = 1000
MAX_VISITED = 100_000
"""Directory entries a listing looks at, at most: a folder holding a huge tree (a home
folder) is listed in part rather than making the page wait."""
SKIPPED_FOLDERS = frozenset({"node_modules", "__pycache__"})


class Refused(Exception):
    """A path the studio does not use (spec/studio.md, "Files"); the message says why."""


class Unusable(Exception):
    """A file that cannot be read or written; the message says why and what to do."""


class Changed(Exception):
    """A file changed since the page read it: saving would lose what changed."""


def version_of(data: bytes) -> str:
    """What a page keeps of a file it read, to save over that content only."""
    return hashlib.sha256(data).hexdigest()


@dataclass(frozen=True, slots=True)
class Entry:
    path: str
    kind: Kind
    size: int

    def to_json(self) -> dict[str, object]:
        return {"path": self.path, "kind": self.kind, "size": self.size}


def kind_of(name: str) -> Kind | None:
    return next((kind for ending, kind in KINDS.items() if name.endswith(ending)), None)


class Folder:
    """The folder the studio was started in, its files addressed by relative paths."""

    def __init__(self, root: str | os.PathLike[str]) -> None:
        self.root = Path(root).resolve(strict=True)

    def relative(self, path: Path) -> str:
        return path.relative_to(self.root).as_posix()

    def resolve(self, path: str) -> Path:
        """Where `path` (relative to the folder, or absolute inside it) leads; Refused
        when it leaves the folder or spells `..`."""
        if len(path) > MAX_PATH:  # quoted whole, a page's 64 MiB would be six times that
            raise Refused(f"`{excerpt(path)}` is longer than {MAX_PATH:,} characters, "
                          "longer than any file's path: give one relative to the folder, "
                          "such as `sample.rob`")
        if not path or "\x00" in path or not _nameable(path):
            raise Refused(f"`{path!r}` is no file's path: give one relative to the folder, "
                          "such as `sample.rob`")
        if path.endswith(("/", "/.")):  # `main.rob/` would name main.rob
            raise Refused(f"`{path}` names a folder: give the path of a file, such as "
                          "`sample.rob`")
        if ".." in PurePosixPath(path).parts or ".." in Path(path).parts:
            raise Refused(f"`{path}` has a `..`: give a path inside {self.root}")
        try:
            resolved = (self.root / path).resolve()
        except (OSError, RuntimeError) as error:  # a loop of symbolic links
            raise Refused(f"`{path}` cannot be followed: {error}") from None
        if not resolved.is_relative_to(self.root):
            raise Refused(f"`{path}` is outside {self.root}, the folder rl1c studio was "
                          "started in, and the studio uses no file outside it: start it "
                          "in a folder that holds the file")
        return resolved

    def read(self, path: str) -> bytes:
        """The bytes of the regular file `path`, at most MAX_FILE_BYTES."""
        resolved = self.resolve(path)
        try:
            descriptor = os.open(resolved, os.O_RDONLY | os.O_NONBLOCK | os.O_NOFOLLOW
                                 | os.O_CLOEXEC)
        except FileNotFoundError:
            raise Unusable(f"`{path}`: no such file in {self.root}") from None
        except OSError as error:
            raise Unusable(f"`{path}` cannot be read: {error.strerror or error}") from None
        try:
            _regular(path, os.fstat(descriptor))
        except Refused:
            os.close(descriptor)
            raise
        with os.fdopen(descriptor, "rb") as stream:
            try:
                data = stream.read(MAX_FILE_BYTES + 1)
            except OSError as error:
                raise Unusable(f"`{path}` cannot be read: {error.strerror or error}") from None
        if len(data) > MAX_FILE_BYTES:
            raise Unusable(f"`{path}` is larger than {MAX_FILE_BYTES // 2**20} MiB, the "
                           "most the studio opens")
        return data

    def save(self, path: str, data: bytes, over: str | None = None) -> None:
        """Put `data` in the file `path` all at once (a program, a world, a sensor
        script), replacing it or making it in an existing folder; when `over` is given,
        only over the content of that version (Changed otherwise)."""
        resolved = self.resolve(path)
        for name in (path, resolved.name):
            if kind_of(name) is None:
                raise Refused(f"`{name}` is no file the studio writes: its name ends in "
                              f"{', '.join(KINDS)}")
        try:
            status = resolved.lstat()
        except FileNotFoundError:
            if not resolved.parent.is_dir():
                raise Unusable(f"`{path}`: the folder {self.relative(resolved.parent)!r} "
                               "does not exist: make it first") from None
        except OSError as error:
            raise Unusable(f"`{path}` cannot be written: {error.strerror or error}") from None
        else:
            _regular(path, status)
        if len(data) > MAX_FILE_BYTES:
            raise Unusable(f"`{path}` would be larger than {MAX_FILE_BYTES // 2**20} MiB, "
                           "the most the studio writes")
        if over is not None:
            try:
                now = version_of(self.read(path))
            except Unusable:
                now = None  # gone, or unreadable: not the version read
            if now != over:
                raise Changed(f"`{path}` has changed since it was read (another program "
                              "wrote it): read it again, or save under another name")
        try:
            write_atomically(resolved, data)
        except OSError as error:
            raise Unusable(f"`{path}` cannot be written: {error.strerror or error}") from None

    def listing(self) -> tuple[list[Entry], bool]:
        """The studio's files in the folder and its subfolders, sorted by path, at most
        MAX_LISTED; and whether some were left out."""
        entries: list[Entry] = []
        visited = 0
        truncated = False
        for folder, folders, names in os.walk(self.root):  # symbolic links to folders not followed
            folders[:] = sorted(name for name in folders
                                if not name.startswith(".") and name not in SKIPPED_FOLDERS)
            visited += len(folders) + len(names)
            for name in sorted(names):
                kind = kind_of(name)
                if kind is None:
                    continue
                place = Path(folder, name)
                try:
                    status = place.stat()
                    inside = place.resolve().is_relative_to(self.root)
                except (OSError, RuntimeError):
                    continue
                size = status.st_size
                if inside and stat.S_ISREG(status.st_mode):  # no FIFO the page would open
                    entries.append(Entry(self.relative(place), kind, size))
            if len(entries) > MAX_LISTED or visited > MAX_VISITED:
                truncated = True
                break
        entries.sort(key=lambda entry: entry.path)
        return entries[:MAX_LISTED], truncated or len(entries) > MAX_LISTED


def _nameable(path: str) -> bool:
    """Whether `path` has a form in the file system's bytes: JSON can carry half of a
    surrogate pair (`\\ud800`), which is no character, and names no file."""
    try:
        os.fsencode(path)
    except UnicodeEncodeError:
        return False
    return True


def _regular(path: str, status: os.stat_result) -> None:
    if stat.S_ISREG(status.st_mode):
        return
    kind = ("a folder" if stat.S_ISDIR(status.st_mode) else
            "a FIFO" if stat.S_ISFIFO(status.st_mode) else
            "a device" if stat.S_ISCHR(status.st_mode) or stat.S_ISBLK(status.st_mode) else
            "a socket" if stat.S_ISSOCK(status.st_mode) else "not a regular file")
    raise Refused(f"`{path}` is {kind}: the studio reads and writes regular files only")
