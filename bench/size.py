"""Code size: the .ilc of Listing 1 (examples/sample.rob) without its debug section,
against the size of its source.

Prints the file's bytes (and the code section's alone), bytes per statement, and the
source's bytes; the debug section's cost is shown beside them.

    .venv/bin/python bench/size.py [FILE.rob]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.frontend.source import read_source
from rl1.vm import ilc

SAMPLE = Path(__file__).parent.parent / "examples" / "sample.rob"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("source", nargs="?", type=Path, default=SAMPLE)
    path: Path = parser.parse_args().source
    size = path.stat().st_size
    text = read_source(str(path)).text
    statements = sum(1 for _ in parse_program(text)[0].statements())
    stripped, full = (compile_text(text, path.name, strip_debug=strip).output
                      for strip in (True, False))
    if stripped is None or full is None:
        raise SystemExit(f"{path} has errors: run `rl1c check {path}`")
    code = len(ilc.decode(stripped).code)
    print(f"{path.name}: {statements} statements, source {size} bytes")
    print(f"  .ilc without debug: {len(stripped)} bytes "
          f"({len(stripped) / statements:.2f} per statement, "
          f"{len(stripped) / size:.0%} of the source)")
    print(f"  code section:       {code} bytes ({code / statements:.2f} per statement)")
    print(f"  .ilc with debug:    {len(full)} bytes (+{len(full) - len(stripped)} for the "
          "line map)")


if __name__ == "__main__":
    main()
