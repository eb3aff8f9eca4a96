"""The world file: what it accepts, and a clear message for everything it does not."""

from __future__ import annotations

import contextlib
import json
import tempfile
from pathlib import Path

import msgspec.inspect as mi
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.hostile import world_attack

from rl1.vm.sim.world import (
    MAX_POINTS,
    LimitsTable,
    Noise,
    Vehicle,
    WorldError,
    decode_world,
    parse_world,
)

SAMPLE_WORLD = Path(__file__).resolve().parents[2] / "examples" / "sample.world.toml"

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
     "w.toml:16: stands[0].facingg: unknown key; did you mean facing? (expected one of name, "
     "x, y, width, depth, facing"),
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
    (b"[floor\n", "w.toml:1: invalid TOML: Expected ']' at the end of a table declaration "
     "(column 7)"),
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


# Physical ranges: every world that loads can be simulated ------------------------------


def _ranged() -> list[tuple[str, str, float, float]]:
    """Each number of [vehicle], [noise] and [limits], with its range from the schema."""
    found = []
    for table, schema in (("vehicle", Vehicle), ("noise", Noise), ("limits", LimitsTable)):
        info = mi.type_info(schema)
        assert isinstance(info, mi.StructType)
        for field in info.fields:
            kind = field.type.type if isinstance(field.type, mi.Metadata) else field.type
            assert isinstance(kind, mi.IntType | mi.FloatType), field.name
            assert kind.ge is not None and kind.le is not None, field.name  # bounded
            found.append((table, field.encode_name, kind.ge, kind.le))
    return found


RANGED = _ranged()


def _beyond(low: float, high: float) -> list[float]:
    below = low - 1 if isinstance(low, int) or low <= 0 else low / 2
    above = high + 1 if isinstance(high, int) else high * 2
    return [below, above]


@pytest.mark.parametrize(("table", "key", "low", "high"), RANGED)
def test_each_quantity_loads_at_its_bounds_and_is_refused_beyond(
        table: str, key: str, low: float, high: float) -> None:
    def world(value: float) -> bytes:
        return GOOD + f"\n[{table}]\n{key} = {value!r}\n".encode()

    for value in (low, high):
        loaded = decode_world(world(value), "w.toml")
        part = loaded.time_limit if table == "limits" else getattr(getattr(loaded, table), key)
        assert part == value
    for value in _beyond(low, high):
        with pytest.raises(WorldError) as refused:
            decode_world(world(value), "w.toml")
        assert str(refused.value).startswith(f"w.toml:27: {table}.{key}: {value!r} is outside "
                                              f"{low!r}..{high!r}; write one within it")


@pytest.mark.parametrize("setting", ["tread = 5e-324", "trace_interval = 5e-324",
                                     "camera_fov = 5e-324", "tilt_down = 2.2e-308"])
def test_tiny_values_that_crashed_the_simulator_are_refused(setting: str) -> None:
    with pytest.raises(WorldError, match=r"w\.toml:27: vehicle\.\w+: [0-9.e-]+ is outside"):
        decode_world(GOOD + f"\n[vehicle]\n{setting}\n".encode(), "w.toml")


def test_the_spec_gives_each_quantity_its_range() -> None:
    spec = (Path(__file__).resolve().parents[2] / "spec" / "simulator.md").read_text()
    for table, key, low, high in RANGED:
        name = key if table == "vehicle" else f"{table}.{key}"
        row = next((line for line in spec.splitlines() if line.startswith(f"| {name} |")), None)
        assert row is not None, (table, key)
        assert f"| {low:g}..{high:g} |" in row, (row, low, high)


def test_a_run_may_take_a_bounded_number_of_tracing_ticks() -> None:
    with pytest.raises(WorldError, match=r"w\.toml:29: limits\.time: a run of 86400 s with "
                                         r"a tracing tick every 0\.001 s"):
        decode_world(GOOD + b"\n[vehicle]\ntrace_interval = 0.001\n[limits]\ntime = 86400\n",
                     "w.toml")


def test_stands_count_against_the_world_s_points() -> None:
    stands = b"".join(b"[[stands]]\nx = 1\ny = 1\nfacing = 0\n" for _ in range(MAX_POINTS // 4))
    with pytest.raises(WorldError, match=r"stands\[2499\]: the world's lines, polygons and "
                                         "stands have more than"):
        decode_world(GOOD + stands, "w.toml")


@pytest.mark.parametrize(("data", "says"), [
    (b'{"IMG": [{"area": 1, "x": 2, "y": 3, "z": 4}]}', "w.toml: this looks like a sensor "
     "script, not a world file: give it to `rl1c run --sensors` (spec/sensors.md)"),
    (b'"ULT A" = [150]\n', "w.toml: this looks like a sensor script (it has `ULT A`), not a "
     "world file: give it to `rl1c run --sensors`"),
])
def test_a_sensor_script_given_as_a_world_is_named_as_one(data: bytes, says: str) -> None:
    with pytest.raises(WorldError) as refused:
        decode_world(data, "w.toml")
    assert str(refused.value).startswith(says)


@pytest.mark.parametrize(("data", "says"), [
    (b"\xef\xbb\xbf" + GOOD, None),  # a byte order mark, refused before
    (GOOD.replace(b'"3" = 7', b'"3" = ' + b"9" * 5000), "w.toml:24: ports.3: a number of "
     "more than 4300 digits"),
    (GOOD.replace(b'"3" = 7', b'"' + b"9" * 5000 + b'" = 7'), "w.toml:24: ports.9999"),
    (GOOD.replace(b'"3" = 7', b'"126" = 7'), "w.toml:24: ports.126: 126 is outside 0..125"),
    # TOML's hexadecimal, octal and binary integers are read without Python's bound.
    (GOOD.replace(b'"3" = 7', b'"3" = 0x' + b"f" * 5000), "w.toml:24: ports.3: a number of "
     "more than 4300 digits"),
    (GOOD.replace(b'"3" = 7', b'"3" = 0b' + b"1" * 20000), "w.toml:24: ports.3: a number of "
     "more than 4300 digits"),
])
def test_keys_and_numbers_of_any_length_are_read_within_bounds(data: bytes,
                                                               says: str | None) -> None:
    if says is None:
        assert decode_world(data, "w.toml").ports == {3: 7}
        return
    with pytest.raises(WorldError) as refused:
        decode_world(data, "w.toml")
    assert str(refused.value).startswith(says) and len(str(refused.value)) < 300


def _value(low: float, high: float) -> st.SearchStrategy[float]:
    if isinstance(low, int) and isinstance(high, int):
        return st.integers(low, high)
    return st.sampled_from([low, high]) | st.floats(low, high)


@st.composite
def loadable_worlds(draw: st.DrawFn) -> bytes:
    """Worlds whose every quantity lies in its range, bounds included, with a short time
    limit; the example world's floor, lines, marks and stands."""
    text = SAMPLE_WORLD.read_text().split("[limits]")[0]
    tables: dict[str, list[str]] = {}
    for table, key, low, high in RANGED:
        if table != "limits" and draw(st.booleans()):
            tables.setdefault(table, []).append(f"{key} = {draw(_value(low, high))!r}")
    for table, settings_ in tables.items():
        text += f"\n[{table}]\n" + "\n".join(settings_) + "\n"
    return (text + f"\n[limits]\ntime = {draw(st.sampled_from([0.1, 0.5, 2.0]))}\n").encode()


@pytest.mark.slow  # each example is a run of rl1c sim
@settings(max_examples=40, deadline=None)
@given(loadable_worlds())
def test_any_world_that_loads_simulates_without_an_internal_error(data: bytes) -> None:
    decode_world(data, "w.toml")  # it loads
    with tempfile.TemporaryDirectory() as folder:
        assert world_attack(data, Path(folder)) == []


_WORLD_KEYS = ["floor", "start", "vehicle", "lines", "marks", "stands", "walls", "scenes",
               "ports", "fuzzy", "noise", "limits", "size", "x", "y", "facing", "points",
               "name", "number", "sees", "window", "tread", "time", "3", "999", "s", "IMG"]
_documents = st.recursive(
    st.none() | st.booleans() | st.integers(-10**6, 10**25) | st.floats()
    | st.text(max_size=4),
    lambda children: st.lists(children, max_size=4)
    | st.dictionaries(st.sampled_from(_WORLD_KEYS), children, max_size=5),
    max_leaves=25,
)


@settings(max_examples=400, deadline=None)
@given(st.dictionaries(st.sampled_from(_WORLD_KEYS), _documents, max_size=6))
def test_any_document_is_a_world_or_a_world_error_naming_the_file(
        document: dict[str, object]) -> None:
    text = json.dumps(document)
    try:
        parse_world(document, text, "w.toml")
    except WorldError as error:
        assert str(error).startswith("w.toml")
