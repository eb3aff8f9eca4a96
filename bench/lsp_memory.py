"""What a language server session holds in memory, against its limits (lsp/server.py's
MAX_OPEN_DOCUMENTS, MAX_OPEN_CHARACTERS, MAX_ANALYSED_IN_ALL): a session is driven in a
fresh process through the interface a transport uses, and its resident memory measured
before and after it opens, and checks:
- as many small documents as a session holds (20 lines of Listing 1 each);
- analysed documents of Listing 1's lines, as many characters as a session analyses;
- documents too large to analyse (lines longer than any analysed), as many characters
  as a session holds;
- a document too large to analyse, as many lines as a session holds, almost all empty.
Prints the growth in MiB, per document and per character (the reference: the text).

    .venv/bin/python bench/lsp_memory.py
"""

from __future__ import annotations

import argparse
import asyncio
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

from lsp_speed import listing_program

from rl1.lsp.document import MAX_ANALYSED_CHARACTERS, MAX_ANALYSED_LINE
from rl1.lsp.server import (
    MAX_ANALYSED_IN_ALL,
    MAX_OPEN_CHARACTERS,
    MAX_OPEN_DOCUMENTS,
    MAX_OPEN_LINES,
    create_server,
)

SETTLE_SECONDS = 0.5  # after the last check has been published


def resident_mib() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise SystemExit("no VmRSS in /proc: this benchmark needs Linux")


def documents(case: str) -> list[str]:
    if case == "small":
        return [listing_program(20)] * MAX_OPEN_DOCUMENTS
    if case == "analysed":
        text = listing_program(MAX_ANALYSED_CHARACTERS // 10)[:MAX_ANALYSED_CHARACTERS]
        return [text[:text.rindex("\n") + 1]] * (MAX_ANALYSED_IN_ALL // len(text))
    line = "A=1;" * (MAX_ANALYSED_LINE // 4 + 1) + "\n"
    if case == "lines":
        return [line + "\n" * (MAX_OPEN_LINES - 2)]
    text = line * (MAX_ANALYSED_CHARACTERS // len(line))
    return [text] * (MAX_OPEN_CHARACTERS // len(text))


class Counted:
    """A transport's writer that counts the diagnostics published."""

    def __init__(self) -> None:
        self.published = 0

    def write(self, data: bytes) -> None:
        self.published += b"publishDiagnostics" in data

    def close(self) -> None:
        pass


async def measure(case: str) -> dict[str, Any]:
    session = create_server()
    written = Counted()
    session.attach(written)

    def send(message: dict[str, Any]) -> None:
        session.receive(json.dumps({"jsonrpc": "2.0", **message}).encode())

    send({"id": 1, "method": "initialize", "params": {"processId": None, "rootUri": None,
                                                      "capabilities": {}}})
    texts = documents(case)
    await asyncio.sleep(SETTLE_SECONDS)
    before = resident_mib()
    for number, text in enumerate(texts):
        send({"method": "textDocument/didOpen", "params": {"textDocument": {
            "uri": f"file:///bench/{number}.rob", "languageId": "rl1", "version": 1,
            "text": text}}})
        while written.published <= number:
            await asyncio.sleep(0.001)
    await asyncio.sleep(SETTLE_SECONDS)
    held = len(session.documents)
    assert held == len(texts), f"{len(texts) - held} documents turned away"
    return {"documents": held, "characters": session.held.characters,
            "lines": session.held.lines, "mib": resident_mib() - before}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", help="measure this case alone (run by the others)")
    if (case := parser.parse_args().case) is not None:
        print(json.dumps(asyncio.run(measure(case))))
        return
    print(f"a session holds {MAX_OPEN_DOCUMENTS:,} documents, {MAX_OPEN_CHARACTERS:,} "
          f"characters, {MAX_OPEN_LINES:,} lines, {MAX_ANALYSED_IN_ALL:,} characters "
          "analysed")
    for case, what in [("small", "small documents (20 lines)"),
                       ("analysed", "analysed documents"),
                       ("unanalysed", "documents too large to analyse"),
                       ("lines", "a document of empty lines")]:
        out = subprocess.run([sys.executable, __file__, "--case", case], check=True,
                             capture_output=True, text=True).stdout
        figures = json.loads(out)
        mib, count, characters = figures["mib"], figures["documents"], figures["characters"]
        print(f"{count:>4} {what:<32} {characters:>11,} characters {figures['lines']:>10,} "
              f"lines {mib:7.1f} MiB  {mib * 2**20 / count / 1024:8.1f} KiB a document  "
              f"{mib * 2**20 / characters:6.1f} bytes a character")


if __name__ == "__main__":
    main()
