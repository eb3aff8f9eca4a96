"""Reading input files within a size bound, and writing output files all at once.

Every OS failure of a read becomes a SourceError whose message says what to do. A write
goes to a temporary file in the target's directory (the same file system, so
the rename is atomic), which then replaces the target. On any failure the temporary file
is removed and the target, if it existed, is left as it was.
"""

from __future__ import annotations

import contextlib
import os
import stat
from pathlib import Path


class SourceError(Exception):
    """An input file that cannot be read, or not as RL/I text; the message says why and
    what to do."""


def read_bounded(path: str | os.PathLike[str], limit: int, what: str) -> bytes:
    """The bytes of the input file `path`, `what` it should be; SourceError when it cannot
    be read or holds more than `limit` bytes (found without reading a huge file whole)."""
    try:
        with open(path, "rb") as stream:
            data = stream.read(limit + 1)
    except FileNotFoundError:
        raise SourceError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise SourceError(f"{path} is a directory, not {what}") from None
    except PermissionError:
        raise SourceError(f"{path}: permission denied") from None
    except OSError as error:
        raise SourceError(f"{path}: cannot read ({error.strerror or error})") from None
    if len(data) > limit:
        raise SourceError(f"{path} is larger than {limit // 2**20} MiB, the limit for {what}")
    return data


def write_atomically(path: str | Path, data: bytes) -> None:
    """Replace the file at `path` with `data`; OSError if that cannot be done."""
    # Imported here: tempfile (with shutil and the compression modules it loads) costs
    # rl1c check, which reads files but writes none, 3 ms of every start.
    import tempfile

    path = Path(path)
    mode = _mode_for(path)
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


def _mode_for(path: Path) -> int:
    """A replaced file keeps its permissions; a new one gets the usual ones (mkstemp's
    are owner-only)."""
    try:
        return stat.S_IMODE(path.stat().st_mode)
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask
