"""The project file rl1.toml as the server sees it: the selection it sets for a document
(what `rl1c check` would report for that file), re-read whenever the file changes."""

from __future__ import annotations

import os
from urllib.parse import unquote, urlparse

from rl1.compiler.reporting.project import (
    ProjectFileError,
    find_project_file,
    load_project_file,
)
from rl1.compiler.reporting.selection import Selection


def folder_of(uri: str) -> str | None:
    """The folder of a `file:` URI's file; None for other schemes (an unsaved buffer)."""
    parsed = urlparse(uri)
    if parsed.scheme != "file":
        return None
    return os.path.dirname(unquote(parsed.path))


class ProjectFiles:
    """The selections of the rl1.toml files met, each kept while its file is unchanged
    (looking one up costs a few `stat` calls, next to a check's milliseconds)."""

    def __init__(self) -> None:
        self._loaded: dict[str, tuple[tuple[int, int], Selection | ProjectFileError]] = {}

    def selection(self, uri: str) -> Selection | ProjectFileError:
        """What the nearest rl1.toml sets for the document `uri`, or why it cannot be
        used."""
        folder = folder_of(uri)
        path = find_project_file(folder) if folder is not None else None
        if path is None:
            return Selection()
        try:
            status = os.stat(path)
        except OSError:
            return Selection()  # gone since it was found: as if it never were
        stamp = (status.st_mtime_ns, status.st_size)
        kept = self._loaded.get(path)
        if kept is None or kept[0] != stamp:
            try:
                outcome: Selection | ProjectFileError = load_project_file(path)
            except ProjectFileError as error:
                outcome = error
            kept = (stamp, outcome)
            self._loaded[path] = kept
        return kept[1]
