"""Writes the .ilc files of spec/vectors (both forms of every vector) into a folder, as
the fuzzer's seeds and the sanitizer runs' inputs. Standard library only, so that the
C checks need no virtual environment."""

from __future__ import annotations

import json
import sys
from pathlib import Path

VECTORS = Path(__file__).resolve().parents[3] / "spec" / "vectors"


def main(folder: str) -> None:
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    count = 0
    for path in sorted(VECTORS.glob("*.json")):
        for vector in json.loads(path.read_text(encoding="utf-8"))["vectors"]:
            for field in ("ilc", "ilc_stripped"):
                (out / f"{vector['name']}.{field}").write_bytes(bytes.fromhex(vector[field]))
                count += 1
    print(f"{count} seed files in {out}")


if __name__ == "__main__":
    main(sys.argv[1])
