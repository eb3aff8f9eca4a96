"""The source file of an .ilc file: the name the compiler records in the debug section,
and finding that file again for `rl1c dis`, which shows its lines only when its digest
matches (a source edited since would put every line beside the wrong instructions).

The recorded name is the source's path relative to the .ilc file's folder, so that a
file compiled with `rl1c examples/sample.rob -o sample.ilc` finds its source from
wherever it is read. `dis` follows a recorded name only within the .ilc file's folder:
a hand-made file could name any file on the machine, or a FIFO that would hang it.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path, PurePath, PurePosixPath

from rl1.compiler.files import SourceError
from rl1.compiler.frontend.source import Source, read_source
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
    return name if len(name.encode("utf-8")) <= ilc.MAX_NAME_SIZE else base


@dataclass(frozen=True)
class FoundSource:
    """The lines to interleave (None: none), and a note for the user on why not or
    with what caveat (None: nothing to say)."""

    lines: Sequence[str] | None
    note: str | None = None


def find_source(debug: ilc.DebugInfo | None, ilc_path: str, named: str | None) -> FoundSource:
    """The source lines of the .ilc file at `ilc_path`: from `named` (the user's
    --source, read whatever the .ilc records: SourceError if unreadable), else from the
    file the debug section records, looked for in the .ilc file's folder."""
    if debug is None:
        return FoundSource(None, f"note: {ilc_path} has no debug section (it was compiled "
                                 "with -s), so no source lines are shown")
    if named is not None:
        return _checked(read_source(named), debug, ilc_path)
    if ilc_path == "-":
        return FoundSource(None, "note: source lines not shown: an .ilc file read from "
                                 "standard input has no folder to find its source in: give "
                                 "the source with --source FILE.rob")
    recorded = PurePath(debug.source_name)
    if recorded.is_absolute() or ".." in recorded.parts or not recorded.name:
        return FoundSource(None, f"note: source lines not shown: {ilc_path} records its "
                                 f"source as `{debug.source_name}`, outside its folder, "
                                 "which dis does not open unless asked: give the source "
                                 "with --source FILE.rob")
    folder = Path(ilc_path).parent
    for candidate in dict.fromkeys((folder / recorded, folder / recorded.name)):
        try:
            if stat.S_ISREG(candidate.stat().st_mode):
                return _checked(read_source(str(candidate)), debug, ilc_path)
        except (OSError, SourceError, ValueError):  # ValueError: a NUL in the name
            continue
    return FoundSource(None, f"note: source lines not shown: `{folder / recorded}`, the "
                             f"source {ilc_path} records, was not found or cannot be read; "
                             "give the source with --source FILE.rob")


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
