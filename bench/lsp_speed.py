"""Language server latency as people edit: the real `rl1-lsp` over standard input and
output, on a 10,000-line program made of Listing 1's lines (examples/sample.rob: its
labels defined once, by the first copy, and every copy's jumps going to them).

Each edit is timed from didChange to the publishDiagnostics of that version, with a
pause between edits as a person makes (so that no two are taken for a burst):
- a line inserted at the top, and deleted again;
- a line inserted in the middle, and deleted again;
- a statement typed into a line (`B=2; `), and removed again;
- a jump added to a line (`?A<#40; `), and removed again;
- a label added to a line (`:50 `), and removed again.
Prints the median and 90th percentile per kind of edit, and, as the reference in the
same run, the time to check the whole document from scratch (didOpen to diagnostics).
Goals: a line inserted at the top and a statement typed into a line, median <= 20 ms.

    .venv/bin/python bench/lsp_speed.py [--lines 10000] [--edits 40]
"""

from __future__ import annotations

import argparse
import asyncio
import random
import re
import shutil
import statistics
import sys
import time
from pathlib import Path

from lsprotocol import types
from pygls.lsp.client import LanguageClient

URI = "file:///bench/program.rob"
SAMPLE = Path(__file__).resolve().parent.parent / "examples" / "sample.rob"
GOAL_MS = 20.0
PAUSE_SECONDS = 0.03  # between edits: a fast typist, never a burst


def listing_program(lines: int) -> str:
    """`lines` lines of Listing 1: the first copy as written, the others without their
    labels (RL/I has one definition per label), so every jump goes to the first copy."""
    listing = SAMPLE.read_text().splitlines()
    unlabelled = [re.sub(r"^:\d\d ?", "", line) for line in listing]
    out = list(listing)
    while len(out) < lines:
        out += unlabelled
    return "\n".join(out[:lines]) + "\n"


class Session:
    """A client of the real server that can wait for a version's diagnostics."""

    def __init__(self) -> None:
        self.client = LanguageClient("lsp-speed", "1")
        self.waiters: dict[tuple[str, int], asyncio.Future[float]] = {}

        @self.client.feature(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)  # type: ignore[untyped-decorator]
        def published(params: types.PublishDiagnosticsParams) -> None:
            now = time.perf_counter()
            waiter = self.waiters.pop((params.uri, params.version or 0), None)
            if waiter is not None and not waiter.done():
                waiter.set_result(now)

    def expect(self, uri: str, version: int) -> asyncio.Future[float]:
        future: asyncio.Future[float] = asyncio.get_running_loop().create_future()
        self.waiters[(uri, version)] = future
        return future

    async def start(self) -> None:
        server = shutil.which("rl1-lsp", path=str(Path(sys.executable).parent))
        if server is None:
            raise SystemExit("rl1-lsp is not installed beside this Python: run `make test`")
        await self.client.start_io(server)
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

    async def change(self, version: int, start: types.Position, end: types.Position,
                     text: str) -> float:
        """Seconds from didChange to the diagnostics of `version`."""
        await asyncio.sleep(PAUSE_SECONDS)
        arrival = self.expect(URI, version)
        began = time.perf_counter()
        self.client.text_document_did_change(types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=URI, version=version),
            content_changes=[types.TextDocumentContentChangePartial(
                range=types.Range(start, end), text=text)]))
        return await asyncio.wait_for(arrival, 600) - began

    async def stop(self) -> None:
        await self.client.shutdown_async(None)
        self.client.exit(None)
        await self.client.stop()  # type: ignore[no-untyped-call]


class Editor:
    """Makes edits as a person would, keeping its own copy of the lines."""

    def __init__(self, session: Session, text: str) -> None:
        self.session = session
        self.lines = text.split("\n")
        self.version = 1

    async def _send(self, start: types.Position, end: types.Position, text: str) -> float:
        self.version += 1
        return await self.session.change(self.version, start, end, text)

    async def insert_line(self, where: int, text: str) -> float:
        self.lines.insert(where, text)
        at = types.Position(where, 0)
        return await self._send(at, at, text + "\n")

    async def delete_line(self, where: int) -> float:
        del self.lines[where]
        return await self._send(types.Position(where, 0), types.Position(where + 1, 0), "")

    async def insert_text(self, line: int, column: int, text: str) -> float:
        old = self.lines[line]
        self.lines[line] = old[:column] + text + old[column:]
        at = types.Position(line, column)
        return await self._send(at, at, text)

    async def delete_text(self, line: int, column: int, length: int) -> float:
        old = self.lines[line]
        self.lines[line] = old[:column] + old[column + length:]
        return await self._send(types.Position(line, column),
                                types.Position(line, column + length), "")


def summary(name: str, seconds: list[float], goal: bool = False) -> None:
    ms = sorted(s * 1000 for s in seconds)
    p90 = ms[min(len(ms) - 1, round(0.9 * (len(ms) - 1)))]
    aim = f"   goal: median <= {GOAL_MS:g} ms" if goal else ""
    print(f"{name:<40} median {statistics.median(ms):7.1f} ms   p90 {p90:7.1f} ms"
          f"   n={len(ms)}{aim}")


async def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=10_000)
    parser.add_argument("--edits", type=int, default=40, help="of each kind")
    options = parser.parse_args()
    rng = random.Random(1997)
    text = listing_program(options.lines)

    session = Session()
    await session.start()
    opened = await session.open(URI, text)
    editor = Editor(session, text)
    middle: int = options.lines // 2

    def plain_line() -> int:
        """A line near the middle that starts with a statement (no label, no indent)."""
        while True:
            line = middle + rng.randrange(-500, 500)
            if re.match(r"[A-Za-z@(]", editor.lines[line]):
                return line

    times: dict[str, list[float]] = {}

    def record(kind: str, seconds: float) -> None:
        times.setdefault(kind, []).append(seconds)

    for _ in range(options.edits):
        record("line inserted at the top", await editor.insert_line(0, "A=1"))
        record("line deleted at the top", await editor.delete_line(0))
        where = middle + rng.randrange(-500, 500)
        record("line inserted in the middle", await editor.insert_line(where, "(MOV 1,1)"))
        record("line deleted in the middle", await editor.delete_line(where))
        line = plain_line()
        record("statement typed into a line", await editor.insert_text(line, 0, "B=2; "))
        record("statement removed from a line", await editor.delete_text(line, 0, 5))
        line = plain_line()
        record("jump added to a line", await editor.insert_text(line, 0, "?A<#40; "))
        record("jump removed from a line", await editor.delete_text(line, 0, 8))
        line = plain_line()
        record("label added to a line", await editor.insert_text(line, 0, ":50 "))
        record("label removed from a line", await editor.delete_text(line, 0, 4))

    scratch = [await session.open(f"file:///bench/scratch{index}.rob", text)
               for index in range(5)]
    await session.stop()

    print(f"{options.lines} lines of Listing 1; didOpen -> first diagnostics "
          f"{opened * 1000:.0f} ms")
    print("didChange -> publishDiagnostics of that version:")
    for kind, seconds in times.items():
        summary(kind, seconds, goal=kind in ("line inserted at the top",
                                              "statement typed into a line"))
    summary("reference: whole document from scratch", scratch)


if __name__ == "__main__":
    asyncio.run(main())
