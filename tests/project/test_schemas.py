"""The JSON Schemas of the configuration files (spec/schemas/) are current: generated
from the msgspec schemas that validate the files, so an editor completes and checks
what the loaders accept."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import msgspec

from rl1.compiler.reporting.project_schema import ProjectFile
from rl1.vm.config import SENSOR_SCRIPT, WORLD
from rl1.vm.sensor_script import ScriptFile
from rl1.vm.sim.world import WorldFile

ROOT = Path(__file__).resolve().parents[2]
GENERATE = ROOT / "spec" / "schemas" / "generate.py"


def test_the_committed_schemas_are_what_the_generator_writes() -> None:
    result = subprocess.run([sys.executable, str(GENERATE), "--check"], capture_output=True,
                            text=True, check=False)
    assert result.returncode == 0, result.stderr


def test_each_schema_names_every_key_its_loader_accepts() -> None:
    for name, schema in (("world", WorldFile), ("sensors", ScriptFile), ("rl1", ProjectFile)):
        document = json.loads((ROOT / "spec" / "schemas" / f"{name}.schema.json").read_text())
        top = document["$defs"][document["$ref"].rsplit("/", 1)[1]]
        keys = {field.encode_name for field in msgspec.structs.fields(schema)}
        assert set(top["properties"]) == keys
        assert top["additionalProperties"] is False  # an unknown key is refused


def test_the_marks_of_each_kind_of_file_are_its_own_keys() -> None:
    world = {field.encode_name for field in msgspec.structs.fields(WorldFile)}
    required = {field.encode_name for field in msgspec.structs.fields(WorldFile)
                if field.required}
    script = {field.encode_name for field in msgspec.structs.fields(ScriptFile)}
    assert set(WORLD.marks) == required  # every world file has them
    assert set(SENSOR_SCRIPT.marks) == script - {"comment"}
    assert not world & script
