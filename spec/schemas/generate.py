"""Write the JSON Schemas of the configuration files, spec/schemas/*.schema.json, from
their msgspec schemas (the same types that validate the files), for editors' completion
and checking: a world file, a sensor script (JSON or TOML), rl1.toml and a test file.

    .venv/bin/python spec/schemas/generate.py           write the files
    .venv/bin/python spec/schemas/generate.py --check   write nothing; exit 1 if a file
                                                        differs from what would be written

tests/project/test_schemas.py runs the check.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import msgspec

from rl1.compiler.files import write_atomically
from rl1.compiler.reporting.project_schema import ProjectFile
from rl1.compiler.test_file import TestFile
from rl1.vm.sensor_script import ScriptFile
from rl1.vm.sim.world import WorldFile

HERE = Path(__file__).resolve().parent

SCHEMAS: dict[str, tuple[type[Any], str]] = {
    "world.schema.json": (WorldFile, "A world file of rl1c sim --world (spec/simulator.md)"),
    "sensors.schema.json": (ScriptFile, "A sensor script of rl1c run --sensors "
                                        "(spec/sensors.md)"),
    "rl1.schema.json": (ProjectFile, "rl1.toml, the project file of rl1c check"),
    "tests.schema.json": (TestFile, "A test file of rl1c test, *.tests.toml (spec/tests.md)"),
}


def schema_text(schema: type[Any], title: str) -> str:
    """The JSON Schema of `schema`, as written to its file."""
    document = {"$schema": "https://json-schema.org/draft/2020-12/schema", "title": title,
                **msgspec.json.schema(schema)}
    return json.dumps(document, indent=2, sort_keys=True) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 if a file is not current")
    options = parser.parse_args()
    stale = []
    for name, (schema, title) in SCHEMAS.items():
        text = schema_text(schema, title)
        path = HERE / name
        if path.exists() and path.read_text(encoding="utf-8") == text:
            continue
        stale.append(name)
        if not options.check:
            write_atomically(str(path), text.encode())
    if options.check and stale:
        print("not current: " + ", ".join(stale) + "; run .venv/bin/python "
              "spec/schemas/generate.py", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
