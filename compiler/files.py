"""Reading input files within a size bound, and writing output files all at once.

Every OS failure of a read becomes a SourceError whose message says what to do. A write
replaces a regular file through a temporary file renamed over it, so that a failure
leaves the old file as it was; it never replaces what is not a regular file, nor a
read-only file unless forced (`write_atomically`).
"""

from __future__ import annotations

import contextlib
import os
import stat
from pathlib import Path
from typing import BinaryIO


class SourceError(Exception):
    """An input file that cannot be read, or not as RL/I text: `path`, why (`reason`,
    such as "no such file") and what to do (`help`). str() is "PATH: REASON"."""

    def __init__(self, path: str | os.PathLike[str], reason: str, help: str = "") -> None:
        super().__init__(f"{path}: {reason}")
        self.path = str(path)
        self.reason = reason
        self.help = help


class TooLargeError(SourceError):
    """An input file larger than its kind of file can be."""


def read_bounded(path: str | os.PathLike[str], limit: int, what: str) -> bytes:
    """The bytes of the input file `path`, `what` it should be; SourceError when it cannot
    be read or holds more than `limit` bytes (found without reading a huge file whole)."""
    try:
        with open(path, "rb") as stream:
            if _standard_output_too(stream):
                raise SourceError(path, "it is where standard output goes too (the shell "
                                  "empties it for `> FILE` before rl1c runs)",
                                  "send the output to another file")
            data = stream.read(limit + 1)
    except FileNotFoundError:
        raise SourceError(path, "no such file", "check the name, and the folder rl1c runs "
                          "in") from None
    except IsADirectoryError:
        raise SourceError(path, f"it is a directory, not {what}",
                          "name a file inside it") from None
    except PermissionError:
        raise SourceError(path, "permission denied",
                          "make the file readable (chmod +r), or name another") from None
    except OSError as error:
        raise SourceError(path, f"cannot read it ({error.strerror or error})") from None
    if len(data) > limit:
        raise TooLargeError(path, f"it is larger than {limit // 2**20} MiB, the limit for "
                          f"{what}", f"check that this is {what}")
    return data


def _standard_output_too(stream: BinaryIO) -> bool:
    """Whether `stream` reads the regular file standard output writes (`rl1c dis x.ilc >
    x.ilc`), as cat refuses to."""
    try:
        read, written = os.fstat(stream.fileno()), os.fstat(1)
    except OSError:  # standard output closed
        return False
    return stat.S_ISREG(written.st_mode) and (read.st_dev, read.st_ino) == (
        written.st_dev, written.st_ino)


class NotReplaceable(OSError):
    """An output that must not be replaced: a read-only file, or something that is not a
    regular file (a directory, a socket, a block device). The message says why."""


def write_atomically(path: str | Path, data: bytes, *, force: bool = False) -> None:
    """Put `data` at `path`; OSError (NotReplaceable among them) if that cannot be done.

    A regular file is replaced all at once: the data goes to a temporary file beside it
    that is then renamed over it, so no reader ever sees half of it and a failure leaves
    the old file as it was. A symbolic link is followed, so the link stays a link. A FIFO
    or a character device (`/dev/stdout`, `/dev/null`) is written as a stream, never
    replaced. A read-only file is refused unless `force`: a rename ignores the file's
    own mode, and so does root."""
    # Imported here: tempfile (with shutil and the compression modules it loads) costs
    # rl1c check, which reads files but writes none, 3 ms of every start.
    import tempfile

    path = Path(os.path.realpath(path))
    try:
        status: os.stat_result | None = path.stat()
    except FileNotFoundError:
        status = None
    if status is not None and not stat.S_ISREG(status.st_mode):
        if stat.S_ISFIFO(status.st_mode) or stat.S_ISCHR(status.st_mode):
            with open(path, "wb") as stream:
                stream.write(data)
            return
        kind = "a directory" if stat.S_ISDIR(status.st_mode) else "not a regular file"
        raise NotReplaceable(f"it is {kind}")
    if status is not None and not force and _read_only(path, status):
        raise NotReplaceable("it is read-only; give --force to replace it anyway")
    mode = stat.S_IMODE(status.st_mode) if status is not None else _new_file_mode()
    descriptor, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.",
                                             suffix=".tmp")
    try:
        with os.fdopen(descriptor, "wb") as out:
            out.write(data)
            out.flush()
            os.fsync(out.fileno())
        os.chmod(temporary, mode)
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise


def refuses_writing(path: str | Path) -> bool:
    """Whether write_atomically would refuse `path` without `force`: an existing file
    that is read-only (for anyone, even root)."""
    try:
        status = os.stat(path)
    except OSError:
        return False
    return _read_only(Path(path), status)


def _read_only(path: Path, status: os.stat_result) -> bool:
    """No write permission bit at all (`chmod 444`), or none for this user."""
    writable_bits = stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH
    return not status.st_mode & writable_bits or not os.access(path, os.W_OK)


def _new_file_mode() -> int:
    """The usual permissions of a new file (mkstemp's are owner-only)."""
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask
