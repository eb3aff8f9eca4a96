"""Writes the .ilc files of spec/vectors (both forms of every run vector, and the
verifier's files) into a folder, as
the fuzzer's seeds and the sanitizer runs' inputs. Standard library only, so that the
C checks need no virtual environment."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "spec" / "vectors"))
from ilc_files import run_files, verifier_files


def main(folder: str) -> None:
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    count = 0
    for name, data in [*run_files(), *verifier_files()]:
        (out / name).write_bytes(data)
        count += 1
    print(f"{count} seed files in {out}")


if __name__ == "__main__":
    main(sys.argv[1])
