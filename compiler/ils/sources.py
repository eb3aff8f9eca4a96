"""The source file of an .ilc file: the name the compiler records in the debug section,
and finding that file again for `rl1c dis`, which shows its lines only when its digest
matches (a source edited since would put every line beside the wrong instructions).

The recorded name is the source's path relative to the .ilc file's folder, so that a
file compiled with `rl1c examples/sample.rob -o build/sample.ilc` finds its source
(`../examples/sample.rob`) from wherever it is read. A hand-made or cloned .ilc file
may name any file (a link beside it may point at `/etc/passwd`), so the file is shown
only when its digest is the one recorded: a file is then shown only to someone who
already had its text. `dis` follows a relative name to a regular file (never a FIFO
that would hang it), reads it within the source size bound, refuses an absolute name,
and takes no source by name from a file without a digest (format 1.0).
"""

from __future__ import annotations

import os
import stat
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path, PurePath, PurePosixPath

from rl1.compiler.files import SourceError
from rl1.compiler.frontend.source import MAX_SOURCE_BYTES, Source, decode, read_source
from rl1.vm import ilc


def recorded_name(source: str, output: str | None) -> str:
    """What the debug section records for `source` compiled to `output` (None or `-`
    for standard output): its path from the output's folder, with `/` separators, or
    its base name when there is no such path or it is too long to record."""
    base = os.path.basename(source)
    if output is None or output == "-" or source == "-":
        return base
    try:
        relative = os.path.relpath(os.path.abspath(source),
                                   os.path.dirname(os.path.abspath(output)))
    except ValueError:  # on another drive
        return base
    name = PurePosixPath(*PurePath(relative).parts).as_posix()
    return name if len(os.fsencode(name)) <= ilc.MAX_NAME_SIZE else base


@dataclass(frozen=True)
class FoundSource:
    """The lines to interleave (None: none), and a note for the user on why not or
    with what caveat (None: nothing to say)."""

    lines: Sequence[str] | None
    note: str | None = None


def find_source(debug: ilc.DebugInfo | None, ilc_path: str, named: str | None) -> FoundSource:
    """The source lines of the .ilc file at `ilc_path`: from `named` (the user's
    --source, read whatever the .ilc records: SourceError if unreadable), else from the
    file the debug section records, from the .ilc file's folder, when its digest is
    the one recorded."""
    if debug is None:
        return FoundSource(None, f"note: {ilc_path} has no debug section (it was compiled "
                                 "with -s), so no source lines are shown")
    if named is not None:
        return _checked(read_source(named), debug, ilc_path)
    give = "give the source with --source FILE.rob"
    if ilc_path == "-":
        return FoundSource(None, "note: source lines not shown: an .ilc file read from "
                                 f"standard input has no folder to find its source in: {give}")
    recorded = PurePath(debug.source_name)
    if recorded.is_absolute() or not recorded.name:
        return FoundSource(None, f"note: source lines not shown: {ilc_path} records its "
                                 f"source as `{debug.source_name}`, which is not a path "
                                 f"from its folder, so dis does not open it: {give}")
    if debug.source_digest is None:
        return FoundSource(None, f"note: source lines not shown: {ilc_path} has no source "
                                 "digest (format 1.0), so the file it names, "
                                 f"`{debug.source_name}`, cannot be told from another: {give}")
    folder = Path(ilc_path).parent
    first_problem = ""
    for candidate in dict.fromkeys((folder / recorded, folder / recorded.name)):
        found, reason = _regular_source(candidate)
        if found is None:
            problem = (f"note: source lines not shown: `{candidate}`, the source {ilc_path} "
                       f"records, {reason}; {give}")
        else:
            shown = _checked(found, debug, ilc_path)
            if shown.lines is not None:
                return shown
            problem = f"{shown.note}, or {give}"
        first_problem = first_problem or problem
    return FoundSource(None, first_problem)


def _regular_source(path: Path) -> tuple[Source | None, str]:
    """The source at `path` (links followed) when it is a regular file that reads as
    RL/I source within the size bound; else None and why not, as a clause."""
    try:  # O_NONBLOCK: opening a FIFO must not wait for a writer (Windows has none)
        descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        return None, "was not found"
    except (OSError, ValueError) as error:  # ValueError: a NUL in the name
        return None, f"cannot be opened ({getattr(error, 'strerror', None) or error})"
    if not stat.S_ISREG(os.fstat(descriptor).st_mode):
        os.close(descriptor)
        return None, "is not a regular file"
    with os.fdopen(descriptor, "rb") as stream:
        try:
            data = stream.read(MAX_SOURCE_BYTES + 1)
        except OSError as error:
            return None, f"cannot be read ({error.strerror or error})"
    if len(data) > MAX_SOURCE_BYTES:
        return None, f"is larger than {MAX_SOURCE_BYTES // 2**20} MiB, the bound of a source"
    try:
        return decode(data, str(path)), ""
    except SourceError as error:
        return None, f"is not RL/I source ({error.reason})"


def _checked(source: Source, debug: ilc.DebugInfo, ilc_path: str) -> FoundSource:
    if debug.source_digest is None:
        return FoundSource(source.lines, f"note: {ilc_path} has no source digest (format "
                                         f"1.0), so {source.name} cannot be checked against "
                                         "the source compiled: if it was edited since, its "
                                         "lines stand beside the wrong instructions")
    if ilc.source_digest(source.text) != debug.source_digest:
        return FoundSource(None, f"warning: source lines not shown: {source.name} is not "
                                 f"the source {ilc_path} was compiled from (it was edited "
                                 "since, or is another file): compile it again")
    return FoundSource(source.lines)
