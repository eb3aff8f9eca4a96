"""The .ilc files the vector documents hold, for the tools that need the files alone
(the C loader's tests, its fuzzer's seeds, the emulated targets' cases). Standard
library only, so that the C checks need no virtual environment."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

VECTORS = Path(__file__).resolve().parent


def _documents() -> Iterator[dict[str, list[dict[str, object]]]]:
    for path in sorted(VECTORS.glob("*.json")):
        yield json.loads(path.read_text(encoding="ascii"))


def run_files() -> Iterator[tuple[str, bytes]]:
    """Both forms of every run vector's program (name.ilc, name.stripped), all valid."""
    for document in _documents():
        for vector in document.get("vectors", []):
            yield f"{vector['name']}.ilc", bytes.fromhex(str(vector["ilc"]))
            yield f"{vector['name']}.stripped", bytes.fromhex(str(vector["ilc_stripped"]))


def verifier_files() -> Iterator[tuple[str, bytes]]:
    """The verifier's files (verifier.json), accepted and refused."""
    for document in _documents():
        for case in document.get("files", []):
            yield f"{case['name']}.file", bytes.fromhex(str(case["ilc"]))
