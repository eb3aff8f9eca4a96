"""The sensor script's loader (vm/sensor_script.py) on the one validation layer: lines
in every message, a world file given as a script, byte order marks and numbers of any
length."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.cli import rl1c

from rl1.vm.sensor_script import ScriptError, decode_script

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "examples" / "sample.rob"
WORLD = ROOT / "examples" / "sample.world.toml"
SENSORS = ROOT / "examples" / "sample.sensors.json"


@pytest.mark.parametrize(("name", "data", "says"), [
    ("s.toml", b'"ULT A" = [1]\n\n[[IMG]]\narea = 1\nx = 2\ny = 3\nz = 40000\n',
     "s.toml:7: IMG[0].z: 40000 is outside -32768..32767; write one within it"),
    ("s.json", b'{"ULT A": [1],\n "INP": {"3": [1,\n  300]}}',
     "s.json:3: INP.3[1]: 300 is outside 0..255"),
    ("s.json", b'{\n "fail": {"CAM X": 1}}', "s.json:2: fail.CAM X: not a built-in form"),
    ("s.json", b'{"ULT A": null}', "s.json:1: ULT A: expected a list of at least one reading"),
    ("s.json", b'{"line_lost": [{"time": null}]}',
     "s.json:1: line_lost[0].time: expected an integer in 1..2147483647, found null"),
    ("s.json", b'{\n "line_lost": [\n  {"during": "MOV"}]}',
     's.json:3: line_lost[0]: expected {"time": MS}, {"instruction": N} or'),
    ("s.json", b'{"INP": {"3": [' + b"9" * 5000 + b"]}}",
     "s.json:1: INP.3[0]: a number of more than 4300 digits"),
    ("s.toml", b'"ULT A" = [' + b"9" * 5000 + b"]\n",
     "s.toml:1: ULT A[0]: a number of more than 4300 digits"),
    ("s.json", b'{"ULT A": [' + b"9" * 400 + b"]}",
     "s.json:1: ULT A[0]: a number of 400 digits is outside -32768..32767"),
    ("s.json", b'{"' + b"k" * 3_000_000 + b'": 1}',
     's.json:1: ' + "k" * 40 + '...: unknown key; expected one of "IMG"'),
])
def test_messages_name_the_line_and_key_and_quote_in_short(name: str, data: bytes,
                                                           says: str) -> None:
    with pytest.raises(ScriptError) as refused:
        decode_script(data, name)
    assert str(refused.value).startswith(says), str(refused.value)[:300]
    assert len(str(refused.value)) < 400


@pytest.mark.parametrize("name", ["s.json", "s.toml"])
def test_a_byte_order_mark_is_accepted(name: str) -> None:
    text = '{"ULT A": [150]}' if name == "s.json" else '"ULT A" = [150]\n'
    assert decode_script(b"\xef\xbb\xbf" + text.encode(), name).ultrasonic == {"A": (150,)}


def test_a_world_file_given_as_a_sensor_script_is_named_as_one() -> None:
    with pytest.raises(ScriptError) as refused:
        decode_script(WORLD.read_bytes(), str(WORLD))
    assert str(refused.value) == (f"{WORLD}: this looks like a world file (it has `floor`), "
                                  "not a sensor script: give it to `rl1c sim --world` "
                                  "(spec/simulator.md)")


def test_rl1c_names_the_kind_of_file_given_to_the_wrong_option() -> None:
    run = rl1c("run", SAMPLE, "--sensors", WORLD)
    assert run.exit_code == 2
    assert "this looks like a world file (it has `floor`), not a sensor script: give it " \
           "to `rl1c sim --world`" in run.stderr
    assert "unknown key" not in run.stderr
    sim = rl1c("sim", SAMPLE, "--world", SENSORS)
    assert sim.exit_code == 2
    assert "this looks like a sensor script, not a world file: give it to `rl1c run " \
           "--sensors`" in sim.stderr
