"""The world file (TOML): the floor, its guidance lines and marks, the work stands with
their markers, walls and obstacles, the scenes, the values behind INP and FZI, the
vehicle's geometry and calibration, noise and the time limit (spec/simulator.md).

Loading never raises anything but WorldError, whose message reads
`file:line: where: what is wrong; what to write`.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field, fields, replace
from typing import Any

from .geometry import Point, rectangle


class WorldError(Exception):
    """A world file that cannot be used; the message says where and what to write."""


@dataclass(frozen=True, slots=True)
class Vehicle:
    """The vehicle's geometry and calibration. Lengths in cm, angles in degrees, times
    in seconds; every field may be set in the world file's [vehicle] table."""

    length: float = 80.0  # body, along the heading
    width: float = 60.0
    tread: float = 50.0  # between the two drive wheels
    wheel_unit: float = 5.0  # cm/s of one unit of wheel speed
    rotate_speed: int = 3  # wheel speed units of each wheel while ROT turns in place
    steer_rate: float = 90.0  # degrees/s of the steering motor
    k1: float = 0.02  # the tracing law's gain on the offset, 1/cm
    k2: float = 0.3  # the tracing law's gain on tan of the angle error
    trace_interval: float = 0.05  # s between two corrections of the tracing law
    camera_ahead: float = 30.0  # the camera's pan axis, ahead of the centre
    camera_height: float = 40.0  # the optical centre above the floor
    camera_fov: float = 22.0  # horizontal field of view
    image_width: int = 256
    image_height: int = 240
    tilt_down: float = 50.0  # below the horizontal, after (CAM D); (CAM U) is level
    pan_rate: float = 180.0  # degrees/s of the pan motor
    tilt_time: float = 0.2  # s for (CAM U) or (CAM D)
    image_time: float = 0.04  # s for one (IMG): a frame and its processing
    ultrasonic_time: float = 0.02  # s for one (ULT)
    ultrasonic_range: float = 100.0  # cm; nothing nearer reads this
    ultrasonic_cone: float = 15.0  # half-angle of each sensor's cone


@dataclass(frozen=True, slots=True)
class Line:
    """A guidance line: a polyline `width` cm wide."""

    name: str
    points: tuple[Point, ...]
    width: float


@dataclass(frozen=True, slots=True)
class Mark:
    """A mark painted on the floor (a branch mark): a polygon."""

    name: str
    points: tuple[Point, ...]


@dataclass(frozen=True, slots=True)
class Stand:
    """A work stand: a rectangle centred on (x, y), `depth` along `facing` (degrees,
    the way its marker looks), `width` across. Its marker sits in the middle of the
    face: two LEDs 6 cm apart vertically, the upper one at the camera's height."""

    name: str
    x: float
    y: float
    width: float
    depth: float
    facing: float

    def corners(self) -> list[Point]:
        return rectangle(self.x, self.y, self.depth, self.width, math.radians(self.facing))

    def marker(self) -> Point:
        """Where the marker is on the floor plan: the middle of the face."""
        heading = math.radians(self.facing)
        return (self.x + self.depth / 2 * math.cos(heading),
                self.y + self.depth / 2 * math.sin(heading))


@dataclass(frozen=True, slots=True)
class Block:
    """A wall or an obstacle: a polygon the vehicle must not touch."""

    name: str
    points: tuple[Point, ...]


@dataclass(frozen=True, slots=True)
class Scene:
    """A recognition set-up of the image processor: which features it sees (a kind,
    "lines", "marks" or "markers", or a feature's name) inside which window of the
    image (x0, y0, x1, y1 in pixels, end exclusive)."""

    sees: tuple[str, ...]
    window: tuple[int, int, int, int]


@dataclass(frozen=True, slots=True)
class Noise:
    """Standard deviations of the sensor noise; all 0 (off) unless the world sets them."""

    image_px: float = 0.0  # on the centroid
    odometry: float = 0.0  # relative, on each wheel's count
    ultrasonic_cm: float = 0.0
    delay: float = 0.0  # s: the camera, image processor and ultrasonic report this late


@dataclass(frozen=True, slots=True)
class World:
    floor: tuple[float, float]  # x from 0 to floor[0], y from 0 to floor[1], cm
    start: tuple[float, float, float]  # x, y (cm), heading (degrees from +x, counterclockwise)
    vehicle: Vehicle = field(default_factory=Vehicle)
    lines: tuple[Line, ...] = ()
    marks: tuple[Mark, ...] = ()
    stands: tuple[Stand, ...] = ()
    blocks: tuple[Block, ...] = ()
    scenes: dict[int, Scene] = field(default_factory=dict)
    ports: dict[int, int] = field(default_factory=dict)
    fuzzy: tuple[int, int] = (0, 0)
    noise: Noise = field(default_factory=Noise)
    time_limit: float = 600.0  # s of simulated time before the run is stopped


# Loading --------------------------------------------------------------------------------

_TOP = ("floor", "start", "vehicle", "lines", "marks", "stands", "walls", "obstacles",
        "scenes", "ports", "fuzzy", "noise", "limits")
_LIMIT = 1e6  # no length, angle or time in a world is near this; larger is a typo
MAX_POINTS = 10_000  # in all lines and polygons: a floor of a few metres needs far fewer


class _Reader:
    """Validates values, naming where they are: `file:line: path`."""

    def __init__(self, text: str, name: str) -> None:
        self.lines = text.splitlines()
        self.name = name
        self.points_seen = 0

    def line_of(self, path: tuple[str | int, ...]) -> int | None:
        """The line where `path` is written, found from the table headers: a best
        effort, since tomllib gives no positions."""
        start, end, depth = 0, len(self.lines), 0
        for step, part in enumerate(path):
            if isinstance(part, int):
                continue
            following = path[step + 1] if step + 1 < len(path) else None
            array = isinstance(following, int)
            header = re.compile(r"^\s*\[\[\s*" + re.escape(part) + r"\s*\]\]" if array
                                else r"^\s*\[\s*" + re.escape(part) + r"\s*\]")
            key = re.compile(r"^\s*\"?" + re.escape(part) + r"\"?\s*=")
            wanted = following if isinstance(following, int) else 0
            found = [i for i in range(start, end) if header.match(self.lines[i])]
            if depth == 0 and len(found) > wanted:
                start = found[wanted] + 1
                end = next((i for i in range(start, len(self.lines))
                            if self.lines[i].lstrip().startswith("[")), len(self.lines))
                depth = 1
                continue
            hit = next((i for i in range(start, end) if key.match(self.lines[i])), None)
            if hit is None:
                return start if depth else None
            return hit + 1
        return start if depth else None

    def fail(self, path: tuple[str | int, ...], message: str) -> WorldError:
        where = ".".join(str(p) if isinstance(p, str) else f"[{p}]" for p in path)
        where = where.replace(".[", "[")
        line = self.line_of(path)
        at = f"{self.name}:{line}" if line is not None else self.name
        return WorldError(f"{at}: {where}: {message}" if where else f"{at}: {message}")

    def table(self, value: object, path: tuple[str | int, ...],
              keys: tuple[str, ...], required: tuple[str, ...] = ()) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(path, f"expected a table with {', '.join(keys)}, "
                                  f"found {_kind(value)}")
        for key in value:
            if key not in keys:
                raise self.fail((*path, key), "unknown key; expected one of "
                                + ", ".join(keys))
        for key in required:
            if key not in value:
                raise self.fail(path, f"missing `{key}`; write `{key} = ...`" if path
                                else f"missing the [{key}] table; add one (spec/simulator.md)")
        return value

    def number(self, value: object, path: tuple[str | int, ...], low: float = -_LIMIT,
               high: float = _LIMIT, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(path, f"expected a number, found {_kind(value)}")
        if positive:
            low = max(low, 0.0)
        if isinstance(value, int) and value.bit_length() > 64:  # too long for a float
            raise self.fail(path, f"a number that long is outside {low:g}..{high:g}; "
                                  "write one within it")
        number = float(value)
        if not math.isfinite(number):
            raise self.fail(path, f"{value} is not a finite number; write one in "
                                  f"{low:g}..{high:g}")
        if positive and number <= 0:
            raise self.fail(path, f"{value} must be greater than 0")
        if not low <= number <= high:
            raise self.fail(path, f"{value} is outside {low:g}..{high:g}; write one within it")
        return number

    def integer(self, value: object, path: tuple[str | int, ...], low: int,
                high: int) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(path, f"expected an integer in {low}..{high}, found {_kind(value)}")
        if not low <= value <= high:
            raise self.fail(path, f"{value} is outside {low}..{high}")
        return value

    def text(self, value: object, path: tuple[str | int, ...]) -> str:
        if not isinstance(value, str):
            raise self.fail(path, f"expected a string, found {_kind(value)}")
        return value

    def array(self, value: object, path: tuple[str | int, ...], what: str) -> list[Any]:
        if not isinstance(value, list):
            raise self.fail(path, f"expected an array of {what}, found {_kind(value)}")
        return value

    def points(self, value: object, path: tuple[str | int, ...], least: int) -> tuple[Point, ...]:
        items = self.array(value, path, "points [x, y]")
        if len(items) < least:
            raise self.fail(path, f"expected at least {least} points [x, y], found {len(items)}")
        result = []
        for i, item in enumerate(items):
            pair = self.array(item, (*path, i), "two numbers")
            if len(pair) != 2:
                raise self.fail((*path, i), f"expected a point [x, y], found {len(pair)} numbers")
            result.append((self.number(pair[0], (*path, i)), self.number(pair[1], (*path, i))))
        return tuple(result)

    def tables(self, document: dict[str, Any], key: str) -> list[Any]:
        items = self.array(document.get(key, []), (key,), f"tables ([[{key}]])")
        return items

    def count(self, points: tuple[Point, ...], path: tuple[str | int, ...]) -> tuple[Point, ...]:
        """`points`, counted against MAX_POINTS for the whole world."""
        self.points_seen += len(points)
        if self.points_seen > MAX_POINTS:
            raise self.fail(path, f"the world's lines and polygons have more than "
                                  f"{MAX_POINTS} points; simplify them (a straight run "
                                  "needs only its two ends)")
        return points


def _kind(value: object) -> str:
    if isinstance(value, bool):
        return "true/false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, str):
        return f'the string "{value[:40]}"'
    return repr(value)


def decode_world(data: bytes, name: str) -> World:
    """A World from the bytes of a world file; WorldError says what is wrong."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise WorldError(f"{name}: not UTF-8 text (byte {error.start})") from None
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise WorldError(f"{name}: invalid TOML: {error}") from None
    except (RecursionError, ValueError):  # nesting, or an integer of thousands of digits
        raise WorldError(f"{name}: invalid TOML: nested too deeply or a number far "
                         "too long") from None
    return parse_world(document, text, name)


def parse_world(document: dict[str, Any], text: str = "", name: str = "<world>") -> World:
    r = _Reader(text, name)
    r.table(document, (), _TOP, required=("floor", "start"))
    floor_table = r.table(document["floor"], ("floor",), ("size",), ("size",))
    size = r.array(floor_table["size"], ("floor", "size"), "two numbers")
    if len(size) != 2:
        raise r.fail(("floor", "size"), "expected [width, depth] in cm, e.g. size = [600, 400]")
    floor = (r.number(size[0], ("floor", "size"), positive=True),
             r.number(size[1], ("floor", "size"), positive=True))
    start_table = r.table(document["start"], ("start",), ("x", "y", "heading"), ("x", "y"))
    start = (r.number(start_table["x"], ("start", "x")), r.number(start_table["y"], ("start", "y")),
             r.number(start_table.get("heading", 0.0), ("start", "heading"), -360, 360))
    if not (0 <= start[0] <= floor[0] and 0 <= start[1] <= floor[1]):
        raise r.fail(("start",), f"({start[0]:g}, {start[1]:g}) is off the floor, "
                                 f"which runs from (0, 0) to ({floor[0]:g}, {floor[1]:g})")
    return World(
        floor=floor, start=start, vehicle=_vehicle(r, document.get("vehicle", {})),
        lines=tuple(_line(r, item, i) for i, item in enumerate(r.tables(document, "lines"))),
        marks=tuple(Mark(_name(r, item, ("marks", i), ("name", "points"), f"mark{i}"),
                         r.count(r.points(item["points"], ("marks", i, "points"), 3),
                                 ("marks", i, "points")))
                    for i, item in enumerate(r.tables(document, "marks"))),
        stands=tuple(_stand(r, item, i) for i, item in enumerate(r.tables(document, "stands"))),
        blocks=tuple(Block(_name(r, item, (kind, i), ("name", "points"), f"{kind}{i}"),
                           r.count(r.points(item["points"], (kind, i, "points"), 3),
                                   (kind, i, "points")))
                     for kind in ("walls", "obstacles")
                     for i, item in enumerate(r.tables(document, kind))),
        scenes=_scenes(r, document.get("scenes", []), document),
        ports=_ports(r, document.get("ports", {})),
        fuzzy=_fuzzy(r, document.get("fuzzy", {})),
        noise=_noise(r, document.get("noise", {})),
        time_limit=r.number(r.table(document.get("limits", {}), ("limits",), ("time",))
                            .get("time", 600.0), ("limits", "time"), 0, 86400, positive=True),
    )


def _name(r: _Reader, item: object, path: tuple[str | int, ...], keys: tuple[str, ...],
          default: str) -> str:
    table = r.table(item, path, keys, tuple(k for k in keys if k == "points"))
    return r.text(table.get("name", default), (*path, "name"))


def _vehicle(r: _Reader, value: object) -> Vehicle:
    names = tuple(f.name for f in fields(Vehicle))
    table = r.table(value, ("vehicle",), names)
    vehicle = Vehicle()
    changes: dict[str, Any] = {}
    for key, item in table.items():
        path = ("vehicle", key)
        if isinstance(getattr(vehicle, key), int):
            high = {"rotate_speed": 12, "image_width": 1024, "image_height": 1024}[key]
            changes[key] = r.integer(item, path, 1, high)
        elif key in ("k1", "k2"):
            changes[key] = r.number(item, path, 0, 100)
        elif key in ("camera_fov", "tilt_down", "ultrasonic_cone"):
            changes[key] = r.number(item, path, 0, 89.9 if key != "camera_fov" else 170,
                                    positive=True)
        else:
            changes[key] = r.number(item, path, positive=True)
    return replace(vehicle, **changes)


def _line(r: _Reader, item: object, i: int) -> Line:
    path: tuple[str | int, ...] = ("lines", i)
    table = r.table(item, path, ("name", "points", "width"), ("points",))
    return Line(r.text(table.get("name", f"line{i}"), (*path, "name")),
                r.count(r.points(table["points"], (*path, "points"), 2), (*path, "points")),
                r.number(table.get("width", 2.0), (*path, "width"), positive=True))


def _stand(r: _Reader, item: object, i: int) -> Stand:
    path: tuple[str | int, ...] = ("stands", i)
    table = r.table(item, path, ("name", "x", "y", "width", "depth", "facing"),
                    ("x", "y", "facing"))
    return Stand(r.text(table.get("name", f"stand{i}"), (*path, "name")),
                 r.number(table["x"], (*path, "x")), r.number(table["y"], (*path, "y")),
                 r.number(table.get("width", 40.0), (*path, "width"), positive=True),
                 r.number(table.get("depth", 40.0), (*path, "depth"), positive=True),
                 r.number(table["facing"], (*path, "facing"), -360, 360))


def _scenes(r: _Reader, value: object, document: dict[str, Any]) -> dict[int, Scene]:
    scenes: dict[int, Scene] = {}
    for i, item in enumerate(r.array(value, ("scenes",), "tables ([[scenes]])")):
        path: tuple[str | int, ...] = ("scenes", i)
        table = r.table(item, path, ("number", "sees", "window"), ("number", "sees"))
        number = r.integer(table["number"], (*path, "number"), 0, 7)
        if number in scenes:
            raise r.fail((*path, "number"), f"scene {number} is defined twice; give each "
                                            "[[scenes]] its own number")
        sees = tuple(r.text(s, (*path, "sees", j))
                     for j, s in enumerate(r.array(table["sees"], (*path, "sees"), "names")))
        window = r.array(table.get("window", [0, 0, 1024, 1024]), (*path, "window"),
                         "four integers")
        if len(window) != 4:
            raise r.fail((*path, "window"), "expected [x0, y0, x1, y1] in pixels")
        x0, y0, x1, y1 = (r.integer(v, (*path, "window"), 0, 1024) for v in window)
        if x1 <= x0 or y1 <= y0:
            raise r.fail((*path, "window"), "expected x0 < x1 and y0 < y1")
        scenes[number] = Scene(sees, (x0, y0, x1, y1))
    known = {"lines", "marks", "markers"} | {
        str(t.get("name")) for kind in ("lines", "marks", "stands")
        for t in document.get(kind, []) if isinstance(t, dict) and "name" in t}
    for i, scene in enumerate(scenes.values()):
        for j, seen in enumerate(scene.sees):
            if seen not in known:
                raise r.fail(("scenes", i, "sees", j),
                             f'"{seen}" is not a kind ("lines", "marks", "markers") nor the '
                             "name of a line, mark or stand")
    return scenes


def _ports(r: _Reader, value: object) -> dict[int, int]:
    if not isinstance(value, dict):
        raise r.fail(("ports",), f'expected a table of port = byte, e.g. "3" = 1, '
                                 f"found {_kind(value)}")
    ports = {}
    for key, item in value.items():
        if not (key.isascii() and key.isdigit() and int(key) <= 125):
            raise r.fail(("ports", key), 'a port is a decimal number 0..125, e.g. "3" = 1')
        ports[int(key)] = r.integer(item, ("ports", key), 0, 255)
    return ports


def _fuzzy(r: _Reader, value: object) -> tuple[int, int]:
    table = r.table(value, ("fuzzy",), ("s", "t"))
    return (r.integer(table.get("s", 0), ("fuzzy", "s"), -32768, 32767),
            r.integer(table.get("t", 0), ("fuzzy", "t"), -32768, 32767))


def _noise(r: _Reader, value: object) -> Noise:
    table = r.table(value, ("noise",), ("image_px", "odometry", "ultrasonic_cm", "delay"))
    return Noise(**{key: r.number(item, ("noise", key), 0, 1000) for key, item in table.items()})
