"""Language server under a burst of edits: the real `rl1-lsp`, a 5,000-line program made
of Listing 1's lines, and 1,000 incremental edits sent as fast as a client can write
them (a paste replayed keystroke by keystroke, a script, a multi-cursor edit).

For each burst, prints the time from the last edit sent to the diagnostics of the last
version, and, as the reference in the same run, the time to check the whole document
from scratch (didOpen to diagnostics): the goal is that the last version's diagnostics
arrive within one check of the last edit (and under 200 ms on 5,000 lines). Also prints
the server's resident memory after each burst, which must stay flat.

    .venv/bin/python bench/lsp_burst.py [--lines 5000] [--edits 1000] [--bursts 5]
"""

from __future__ import annotations

import argparse
import asyncio
import random
import statistics
import time
from pathlib import Path

from lsp_speed import URI, Editor, Session, listing_program
from lsprotocol import types

GOAL_MS = 200.0


def resident_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise SystemExit("no VmRSS in /proc: this benchmark needs Linux")


async def burst(editor: Editor, edits: int, rng: random.Random) -> float:
    """Sends `edits` edits without waiting, alternately typing a statement into a line
    and removing it again; returns seconds from the last one sent to its diagnostics."""
    session = editor.session
    typed: list[int] = []
    for index in range(edits):
        editor.version += 1
        if index % 2 == 0:
            line = rng.randrange(len(editor.lines) - 1)
            typed.append(line)
            editor.lines[line] = "B=(" + editor.lines[line]  # an error, then gone again
            start = end = types.Position(line, 0)
            text = "B=("
        else:
            line = typed.pop()
            editor.lines[line] = editor.lines[line][3:]
            start, end, text = types.Position(line, 0), types.Position(line, 3), ""
        if index == edits - 1:
            arrival = session.expect(URI, editor.version)
            sent = time.perf_counter()
        session.client.text_document_did_change(types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(version=editor.version, uri=URI),
            content_changes=[types.TextDocumentContentChangePartial(
                range=types.Range(start, end), text=text)]))
    return await asyncio.wait_for(arrival, 600) - sent


async def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=5_000)
    parser.add_argument("--edits", type=int, default=1_000, help="per burst (even)")
    parser.add_argument("--bursts", type=int, default=5)
    options = parser.parse_args()
    rng = random.Random(1997)
    text = listing_program(options.lines)

    session = Session()
    await session.start()
    server = session.client._server  # the subprocess, for its memory
    assert server is not None
    await session.open(URI, text)
    editor = Editor(session, text)
    print(f"{options.lines:,} lines of Listing 1; bursts of {options.edits:,} edits")
    print(f"server memory after opening: {resident_mib(server.pid):6.1f} MiB")
    latencies = []
    for number in range(1, options.bursts + 1):
        latency = await burst(editor, options.edits, rng)
        latencies.append(latency)
        print(f"burst {number}: last edit -> its diagnostics {latency * 1000:7.1f} ms   "
              f"server memory {resident_mib(server.pid):6.1f} MiB")
    scratch = [await session.open(f"file:///bench/scratch{index}.rob", text)
               for index in range(5)]
    await session.stop()
    median = statistics.median(latencies) * 1000
    reference = statistics.median(scratch) * 1000
    print(f"median after a burst: {median:.1f} ms; reference, one whole check from "
          f"scratch: {reference:.1f} ms; ratio {median / reference:.2f} "
          f"(goal: <= 1, and <= {GOAL_MS:g} ms)")


if __name__ == "__main__":
    asyncio.run(main())
