"""The world file: what it accepts, and a clear message for everything it does not."""

from __future__ import annotations

import contextlib

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rl1.vm.sim.world import WorldError, decode_world

GOOD = b"""
[floor]
size = [600, 400]

[start]
x = 60
y = 200

[[lines]]
name = "guide"
points = [[0, 200], [600, 200]]

[[stands]]
x = 400
y = 330
facing = -135

[[scenes]]
number = 2
sees = ["markers"]
window = [0, 0, 256, 240]

[ports]
"3" = 7
"""


def test_a_good_world_loads_with_defaults_filled_in() -> None:
    world = decode_world(GOOD, "w.toml")
    assert world.floor == (600.0, 400.0)
    assert world.start == (60.0, 200.0, 0.0)
    assert world.lines[0].width == 2.0
    assert world.stands[0].width == 40.0
    assert world.scenes[2].sees == ("markers",)
    assert world.ports == {3: 7}
    assert world.noise.image_px == 0.0  # noise is off by default


@pytest.mark.parametrize(("text", "expected"), [
    (b"[floor]\nsize = [600, 400]\n", "w.toml: missing the [start] table"),
    (GOOD.replace(b"x = 60", b"x = 6000"), "w.toml:5: start: (6000, 200) is off the floor"),
    (GOOD.replace(b"x = 400", b'x = "far"'),
     'w.toml:14: stands[0].x: expected a number in -1e+06..1e+06, found the string "far"'),
    (GOOD.replace(b"facing", b"facingg"),
     "w.toml:16: stands[0].facingg: unknown key; expected one of name, x, y, width, depth, "
     "facing"),
    (GOOD.replace(b'["markers"]', b'["nothing"]'),
     'w.toml:20: scenes[0].sees[0]: "nothing" is not a kind'),
    (GOOD.replace(b"[[0, 200], [600, 200]]", b"[[0, 200]]"),
     "w.toml:11: lines[0].points: expected an array of at least 2 points [x, y], found an "
     "array of 1 item"),
    (GOOD.replace(b'"3" = 7', b'"3" = 700'), "w.toml:24: ports.3: 700 is outside 0..255"),
    (GOOD + b"\n[vehicle]\ntread = -5\n", "w.toml:27: vehicle.tread: -5 is outside 10..1000"),
    (GOOD.replace(b"x = 400", b"x = nan"),
     "w.toml:14: stands[0].x: nan is not a finite number; write one in -1e+06..1e+06"),
    (GOOD.replace(b"x = 400", b"x = " + b"9" * 400),
     "w.toml:14: stands[0].x: a number of 400 digits is outside -1e+06..1e+06"),
    (GOOD + b"\n[[walls]]\npoints = [" + b", ".join(b"[%d, 1]" % i for i in range(10_001)) + b"]\n",
     "w.toml:27: walls[0].points: the world's lines, polygons and stands have more than 10000 "
     "points"),
    (b"[floor\n", "w.toml: invalid TOML"),
    (b"\xff\xfe", "w.toml: not UTF-8 text"),
])
def test_errors_say_where_and_what(text: bytes, expected: str) -> None:
    with pytest.raises(WorldError) as caught:
        decode_world(text, "w.toml")
    assert str(caught.value).startswith(expected), str(caught.value)


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=400) | st.text(max_size=400).map(str.encode))
def test_any_bytes_load_or_give_a_world_error(data: bytes) -> None:
    with contextlib.suppress(WorldError):
        decode_world(data, "w.toml")


@settings(max_examples=200, deadline=None)
@given(st.dictionaries(st.sampled_from(["x", "y", "heading", "width", "facing", "name"]),
                       st.one_of(st.integers(), st.floats(), st.text(max_size=5),
                                 st.booleans(), st.lists(st.integers(), max_size=3)),
                       max_size=6))
def test_any_stand_table_loads_or_gives_a_world_error(table: dict[str, object]) -> None:
    import tomllib

    from rl1.vm.sim.world import parse_world
    document = tomllib.loads(GOOD.decode())
    document["stands"] = [table]
    with contextlib.suppress(WorldError):
        parse_world(document, GOOD.decode(), "w.toml")
