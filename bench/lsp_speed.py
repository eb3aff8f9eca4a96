"""Language server latency over a real stdio session on a generated 10,000-line program.

Reports the median and 95th percentile of: didChange to publishDiagnostics after a
one-line edit inside a line, and after an edit that inserts a line (every line below
moves); hover, definition and completion; and, in the same run, checking the document
from scratch (didOpen of the same text to publishDiagnostics), for the ratio.
Goals: one-line edit to diagnostics <= 20 ms median and >= 20x faster than from
scratch; hover, definition and completion <= 5 ms.

    .venv/bin/python bench/lsp_speed.py [--lines 10000] [--edits 60]
"""

from __future__ import annotations

import argparse
import asyncio
import random
import re
import statistics
import sys
import time
from collections.abc import Awaitable, Callable

from lsprotocol import types
from parse_check import rl1_program
from pygls.lsp.client import LanguageClient

URI = "file:///bench/program.rob"


class Session:
    """A client that can wait for the diagnostics of a given document version."""

    def __init__(self) -> None:
        self.client = LanguageClient("lsp-speed", "1")
        self.waiters: dict[tuple[str, int | None], asyncio.Future[float]] = {}

        @self.client.feature(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)  # type: ignore[untyped-decorator]
        def published(params: types.PublishDiagnosticsParams) -> None:
            key = (params.uri, params.version)
            now = time.perf_counter()
            waiter = self.waiters.pop(key, None)
            if waiter is not None and not waiter.done():
                waiter.set_result(now)

    def expect(self, uri: str, version: int) -> asyncio.Future[float]:
        future: asyncio.Future[float] = asyncio.get_running_loop().create_future()
        self.waiters[(uri, version)] = future
        return future

    async def start(self) -> None:
        await self.client.start_io(sys.executable, "-m", "rl1.lsp")
        await self.client.initialize_async(types.InitializeParams(
            capabilities=types.ClientCapabilities()))
        self.client.initialized(types.InitializedParams())

    async def open(self, uri: str, text: str) -> float:
        """Seconds from didOpen to the first diagnostics."""
        arrival = self.expect(uri, 1)
        start = time.perf_counter()
        self.client.text_document_did_open(types.DidOpenTextDocumentParams(
            types.TextDocumentItem(uri=uri, language_id="rl1", version=1, text=text)))
        return await asyncio.wait_for(arrival, 600) - start

    async def edit(self, version: int, line: int, start: int, end: int, text: str) -> float:
        """Seconds from didChange to the diagnostics of the new version."""
        arrival = self.expect(URI, version)
        began = time.perf_counter()
        self.client.text_document_did_change(types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=URI, version=version),
            content_changes=[types.TextDocumentContentChangePartial(
                range=types.Range(types.Position(line, start), types.Position(line, end)),
                text=text)]))
        return await asyncio.wait_for(arrival, 600) - began

    async def stop(self) -> None:
        await self.client.shutdown_async(None)
        self.client.exit(None)
        await self.client.stop()  # type: ignore[no-untyped-call]


def summary(name: str, seconds: list[float], goal_ms: float | None = None) -> float:
    ms = sorted(s * 1000 for s in seconds)
    median = statistics.median(ms)
    p95 = ms[min(len(ms) - 1, round(0.95 * (len(ms) - 1)))]
    goal = f"   (goal: median <= {goal_ms:g} ms)" if goal_ms is not None else ""
    print(f"{name:<42} median {median:8.2f} ms   p95 {p95:8.2f} ms   n={len(ms)}{goal}")
    return median


async def timed(request: Callable[[], Awaitable[object]], count: int) -> list[float]:
    times = []
    for _ in range(count):
        start = time.perf_counter()
        await request()
        times.append(time.perf_counter() - start)
    return times


async def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=10_000)
    parser.add_argument("--edits", type=int, default=60)
    parser.add_argument("--requests", type=int, default=200)
    options = parser.parse_args()
    rng = random.Random(1997)
    text = rl1_program(options.lines)
    lines = text.splitlines()

    session = Session()
    await session.start()
    opened = await session.open(URI, text)
    print(f"{options.lines} lines; first diagnostics after didOpen: {opened * 1000:.0f} ms")

    # One-line edits: rewrite a number inside a line (the line count stays).
    numbered = [(n, m) for n, line in enumerate(lines) for m in re.finditer(r"\d+", line)][:5000]
    in_line = []
    version = 1
    for _ in range(options.edits):
        version += 1
        number, match = rng.choice(numbered)
        digits = str(rng.randint(0, 99)).rjust(len(match.group()), "0")[: len(match.group())]
        in_line.append(await session.edit(version, number, match.start(), match.end(), digits))
    # Line-inserting edits: every line below the edit moves down.
    inserting = []
    for _ in range(max(options.edits // 4, 3)):
        version += 1
        where = rng.randrange(len(lines))
        lines.insert(where, "A=1")
        inserting.append(await session.edit(version, where, 0, 0, "A=1\n"))

    # Requests on the settled document: a variable, a jump `?A<#NN`, and completion
    # of the label after its `#`.
    identifier = types.TextDocumentIdentifier(URI)
    jump_lines = [n for n, line in enumerate(lines) if line.startswith("?A<#")]
    client = session.client

    def hover_request() -> Awaitable[object]:
        number = rng.randrange(len(lines))
        return client.text_document_hover_async(types.HoverParams(
            identifier, types.Position(number, 1)))

    def definition_request() -> Awaitable[object]:
        number = rng.choice(jump_lines)
        return client.text_document_definition_async(types.DefinitionParams(
            identifier, types.Position(number, 5)))

    def completion_request() -> Awaitable[object]:
        number = rng.choice(jump_lines)
        return client.text_document_completion_async(types.CompletionParams(
            identifier, types.Position(number, 4)))

    hovers = await timed(hover_request, options.requests)
    definitions = await timed(definition_request, options.requests)
    completions = await timed(completion_request, options.requests)

    scratch = [await session.open(f"file:///bench/scratch{index}.rob", text)
               for index in range(3)]
    await session.stop()

    print()
    edit_median = summary("didChange -> diagnostics, edit in a line", in_line, 20)
    summary("didChange -> diagnostics, line inserted", inserting)
    summary("hover", hovers, 5)
    summary("definition", definitions, 5)
    summary("completion (labels after #)", completions, 5)
    scratch_median = summary("from scratch: didOpen -> diagnostics", scratch)
    print(f"\nedit in a line vs from scratch: {scratch_median / edit_median:.1f}x faster "
          "(goal >= 20x)")


if __name__ == "__main__":
    asyncio.run(main())
