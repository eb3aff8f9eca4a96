"""Diagnostics: what they are for a document, how the client sees them, and when they
are published.

A change is checked at once when it comes alone, as a keystroke does; a change that
follows the last one within a few milliseconds (a paste, a multi-cursor edit, a burst
from a script) is part of a burst, whose check waits a little so that the burst is
checked once. The check yields to the event loop while it parses, so requests are
answered in the meantime, and it gives up as soon as a newer version arrives:
diagnostics are never published for a stale version.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from lsprotocol import types

from rl1.compiler import checker
from rl1.compiler.frontend.collector import collector_paused
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity, sort_key
from rl1.compiler.reporting import catalogue
from rl1.compiler.reporting.project import ProjectFileError
from rl1.compiler.reporting.selection import Selection

from .document import MAX_ANALYSED_CHARACTERS, MAX_ANALYSED_LINE, Document
from .positions import Columns
from .project import ProjectFiles
from .test_files import is_test_file_uri, test_file_diagnostics

log = logging.getLogger(__name__)

SOURCE = "rl1"
BURST_SECONDS = 0.005
"""Changes closer together than this are a burst; a burst's check waits this long."""
PARSE_SLICE = 500  # lines parsed between two chances for requests to run

_SEVERITIES = {
    Severity.ERROR: types.DiagnosticSeverity.Error,
    Severity.WARNING: types.DiagnosticSeverity.Warning,
    Severity.INFO: types.DiagnosticSeverity.Information,
}


@dataclass(frozen=True, slots=True)
class Checked:
    """The diagnostics of one version of a document."""

    version: int
    diagnostics: list[Diagnostic]
    checker_failed: bool = False  # the whole-program rules crashed (logged)
    project_error: str | None = None  # why the rl1.toml that applies cannot be used


def diagnose(document: Document, projects: ProjectFiles | None = None) -> Checked:
    """Every diagnostic of the document, as `rl1c check` reports them: each line's own
    (cached), then the whole program's rules, less what its comments allow, as the
    nearest rl1.toml selects them."""
    found = document.problems()
    failed = False
    program = document.program()
    try:
        with collector_paused():
            found.extend(checker.check_program(program, document.memo))
    except Exception:  # a checker bug must not cost the user the syntax errors
        log.exception("the whole-program checker failed on %s", document.uri)
        failed = True
    found = checker.apply_suppressions(program, found, complete=not failed)
    selection = projects.selection(document.uri) if projects is not None else Selection()
    problem = None
    if isinstance(selection, ProjectFileError):
        problem, selection = str(selection), Selection()
    found = selection.apply(found)
    found.sort(key=sort_key)
    return Checked(document.version, found, failed, problem)


@cache
def explanation_uri(code: str) -> str | None:
    """A file URI to the long explanation of `code` (what `rl1c explain` prints)."""
    path = Path(catalogue.__file__).with_name("explanations") / f"{code}.md"
    return path.resolve().as_uri() if path.is_file() else None


def to_lsp(diagnostic: Diagnostic, document: Document, columns: Columns) -> types.Diagnostic:
    message = diagnostic.message
    if diagnostic.help:
        message += f"\nhelp: {diagnostic.help}"
    href = explanation_uri(diagnostic.code)
    return types.Diagnostic(
        range=document.range_of(diagnostic.span, columns),
        message=message,
        severity=_SEVERITIES[diagnostic.severity],
        code=diagnostic.code,
        code_description=types.CodeDescription(href=href) if href else None,
        source=SOURCE,
        related_information=[
            types.DiagnosticRelatedInformation(
                location=types.Location(document.uri, document.range_of(related.span, columns)),
                message=related.message,
            )
            for related in diagnostic.related
        ] or None,
    )


def notice(message: str) -> types.Diagnostic:
    """A diagnostic about the server itself, on the first character."""
    return types.Diagnostic(
        range=types.Range(types.Position(0, 0), types.Position(0, 0)),
        message=message, severity=types.DiagnosticSeverity.Warning, source=SOURCE,
    )


def too_large_notice(document: Document) -> types.Diagnostic:
    if document.size > MAX_ANALYSED_CHARACTERS:
        what = (f"this document has {document.size:,} characters; rl1-lsp analyses "
                f"documents of up to {MAX_ANALYSED_CHARACTERS:,}")
    else:
        number, length = document.longest_line()
        what = (f"line {number} of this document has {length:,} characters; rl1-lsp "
                f"analyses documents whose lines have up to {MAX_ANALYSED_LINE:,}")
    return notice(f"{what}, so it shows no diagnostics and answers no requests for it. "
                  "Check it with `rl1c check FILE`.")


def over_limits_notice(limit: str) -> types.Diagnostic:
    """Why an open document is not held: `limit` says which of the server's."""
    return notice(f"rl1-lsp holds at most {limit} for one client, and this document "
                  "would go past that, so it is not analysed. Close some documents and "
                  "reopen this one, or check it with `rl1c check FILE`.")


def project_notice(problem: str) -> types.Diagnostic:
    return notice(f"rl1-lsp: {problem}. Until it is corrected, every diagnostic is shown "
                  "as if there were no rl1.toml.")


CHECKER_FAILED = notice(
    "rl1-lsp: the whole-program checker failed on this document (an internal error, "
    "logged on the server's standard error), so only syntax and per-line problems are "
    "shown. Please report it with the program that caused it.")


Publish = Callable[[types.PublishDiagnosticsParams], None]


def wait_before_check(previous_change: float | None, now: float) -> float:
    """Seconds to wait before checking a change made at `now`: none for a change alone,
    BURST_SECONDS for one that follows the previous change of its document closely."""
    in_burst = previous_change is not None and now - previous_change < BURST_SECONDS
    return BURST_SECONDS if in_burst else 0.0


class DiagnosticsScheduler:
    """Runs the check of each open document (waiting out bursts of changes) and
    publishes the result."""

    def __init__(self, publish: Publish, columns: Callable[[], Columns]) -> None:
        self._publish = publish
        self._columns = columns
        self._tasks: dict[str, asyncio.Task[None]] = {}
        self._results: dict[str, Checked] = {}
        self._last_change: dict[str, float] = {}
        self._waiting: dict[str, Document] = {}  # checks that have not started yet
        self._projects = ProjectFiles()

    def schedule(self, document: Document) -> None:
        """Check the document's current version soon. A change that joins a burst
        leaves the burst's waiting check in place, which checks whatever version is
        current when the burst ends: a task per change would cost more than the edit."""
        uri = document.uri
        self._results.pop(uri, None)
        loop = asyncio.get_running_loop()
        now = loop.time()
        wait = wait_before_check(self._last_change.get(uri), now)
        self._last_change[uri] = now
        if wait and self._waiting.get(uri) is document:
            return
        self.cancel(uri)
        self._waiting[uri] = document
        task = loop.create_task(self._run(document, wait))
        self._tasks[uri] = task
        task.add_done_callback(self._finished)

    def cancel(self, uri: str) -> None:
        task = self._tasks.pop(uri, None)
        if task is not None:
            task.cancel()
        self._results.pop(uri, None)
        self._waiting.pop(uri, None)

    def close(self, uri: str) -> None:
        """Forget a closed document and clear its diagnostics in the client."""
        self.cancel(uri)
        self._last_change.pop(uri, None)
        self._publish(types.PublishDiagnosticsParams(uri=uri, diagnostics=[]))

    def stop(self) -> None:
        """The session is over: cancel every check."""
        for uri in list(self._tasks):
            self.cancel(uri)

    def current(self, document: Document) -> list[Diagnostic]:
        """The diagnostics of the document's current version, checking it now if the
        scheduled check has not run yet (a code action may ask first)."""
        return self._checked(document).diagnostics

    def _checked(self, document: Document) -> Checked:
        checked = self._results.get(document.uri)
        if checked is None or checked.version != document.version:
            checked = diagnose(document, self._projects)
            self._results[document.uri] = checked
        return checked

    async def _run(self, document: Document, wait: float) -> None:
        await asyncio.sleep(wait)
        loop = asyncio.get_running_loop()
        while wait and (quiet := loop.time() - self._last_change[document.uri]) < BURST_SECONDS:
            await asyncio.sleep(BURST_SECONDS - quiet)  # the burst goes on
        del self._waiting[document.uri]
        version = document.version
        if document.too_large:
            self._send(document, version, [too_large_notice(document)])
            return
        if is_test_file_uri(document.uri):  # TOML, not RL/I: what rl1c test would refuse
            self._send(document, version, test_file_diagnostics(document, self._columns()))
            return
        waiting = document.unprepared()
        for first in range(waiting.start, waiting.stop, PARSE_SLICE):
            document.prepare(first, min(first + PARSE_SLICE, waiting.stop) - 1)
            await asyncio.sleep(0)
            if document.version != version:
                return
        columns = self._columns()
        checked = self._checked(document)
        found = [to_lsp(d, document, columns) for d in checked.diagnostics]
        if checked.project_error is not None:
            found.insert(0, project_notice(checked.project_error))
        self._send(document, version, [CHECKER_FAILED, *found] if checked.checker_failed else found)

    def _send(self, document: Document, version: int, diagnostics: list[types.Diagnostic]) -> None:
        current = self._tasks.get(document.uri) is asyncio.current_task()
        if document.version != version or not current:
            return  # stale: a newer version or a closed document
        self._publish(types.PublishDiagnosticsParams(
            uri=document.uri, diagnostics=diagnostics, version=version,
        ))

    def _finished(self, task: asyncio.Task[None]) -> None:
        if not task.cancelled() and task.exception() is not None:
            log.error("checking a document failed", exc_info=task.exception())
