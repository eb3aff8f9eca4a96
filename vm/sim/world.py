"""The world file (TOML): the floor, its guidance lines and marks, the work stands with
their markers, walls and obstacles, the scenes, the values behind INP and FZI, the
vehicle's geometry and calibration, noise and the time limit (spec/simulator.md).

The file's schema is the msgspec Structs below (`WorldFile`, with `Vehicle` and `Noise`,
which the simulator uses as they are); each number carries its physical range, so that
every world that loads can be simulated. Loading never raises anything but WorldError,
whose message reads `file:line: where: what is wrong; what to write`
(rl1.vm.config, the configuration files' one validation layer).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from typing import Annotated, Any

import msgspec
import msgspec.inspect as mi
from msgspec import UNSET, Meta, Struct, UnsetType

from ..config import (
    INPUT_PORTS,
    SENSOR_SCRIPT,
    WORLD,
    Byte,
    ConfigError,
    Int16,
    PortName,
    convert,
    error_at,
    read_document,
    unknown_key,
)
from ..config_lines import KeyPath
from .geometry import Point, rectangle
from .goal import Goal, Hold, Judge, Region
from .motion import Pose
from .vary import (
    Parameter,
    Varied,
    VaryTable,
    check_bounds,
    distribution,
    entries,
    key_of,
    split_key,
    uniform_draw,
    wrong_key,
)


class WorldError(Exception):
    """A world file that cannot be used; the message says where and what to write."""


def _in(low: float, high: float, unit: str, meaning: str) -> Meta:
    """A number's physical range, low..high (spec/simulator.md), and what it is."""
    return Meta(ge=low, le=high, description=f"{meaning} ({unit})")


_LIMIT = 1e6  # no coordinate in a world is near this; larger is a typo
Coordinate = Annotated[float, _in(-_LIMIT, _LIMIT, "cm", "a coordinate")]
Angle = Annotated[float, _in(-360, 360, "degrees", "from +x, counterclockwise")]
PointValue = Annotated[tuple[Coordinate, Coordinate],
                       Meta(extra={"expected": "a point [x, y] in cm", "plural": "points [x, y]"})]
Name = Annotated[str, Meta(min_length=1, max_length=64, description="what scenes see it by")]


class Vehicle(Struct, frozen=True, forbid_unknown_fields=True):
    """The vehicle's geometry and calibration. Lengths in cm, angles in degrees, times
    in seconds; every field may be set in the world file's [vehicle] table, within its
    physical range."""

    length: Annotated[float, _in(10, 1000, "cm", "body, along the heading")] = 80.0
    width: Annotated[float, _in(10, 1000, "cm", "body, across")] = 60.0
    tread: Annotated[float, _in(10, 1000, "cm", "between the two drive wheels")] = 50.0
    wheel_unit: Annotated[float, _in(0.1, 100, "cm/s", "one unit of wheel speed")] = 5.0
    rotate_speed: Annotated[int, Meta(ge=1, le=12, description=(
        "wheel speed units of each wheel while ROT turns in place"))] = 3
    steer_rate: Annotated[float, _in(1, 3600, "deg/s", "the steering motor")] = 90.0
    k1: Annotated[float, _in(0, 100, "1/cm", "the tracing law's gain on the offset")] = 0.02
    k2: Annotated[float, _in(0, 100, "1", "the tracing law's gain on tan(angle)")] = 0.3
    trace_interval: Annotated[float, _in(0.001, 1, "s", "between two corrections")] = 0.05
    camera_ahead: Annotated[float, _in(0, 1000, "cm", "pan axis ahead of the centre")] = 30.0
    camera_height: Annotated[float, _in(1, 1000, "cm", "optical centre's height")] = 40.0
    camera_fov: Annotated[float, _in(1, 170, "deg", "horizontal field of view")] = 22.0
    image_width: Annotated[int, Meta(ge=1, le=1024, description="pixels")] = 256
    image_height: Annotated[int, Meta(ge=1, le=1024, description="pixels")] = 240
    tilt_down: Annotated[float, _in(1, 89, "deg", "below level after (CAM D)")] = 50.0
    pan_rate: Annotated[float, _in(1, 3600, "deg/s", "the pan motor")] = 180.0
    tilt_time: Annotated[float, _in(0.01, 10, "s", "(CAM U) or (CAM D)")] = 0.2
    image_time: Annotated[float, _in(0.001, 10, "s", "one (IMG), frame and processing")] = 0.04
    ultrasonic_time: Annotated[float, _in(0.001, 10, "s", "one (ULT)")] = 0.02
    ultrasonic_range: Annotated[float, _in(1, 1000, "cm", "the sensors' reach")] = 100.0
    ultrasonic_cone: Annotated[float, _in(1, 89, "deg", "half-angle of each cone")] = 15.0
    instruction_time: Annotated[float, _in(1e-5, 0.01, "s", (
        "the interpreter's time for one instruction of intermediate code"))] = 2e-4


class Noise(Struct, frozen=True, forbid_unknown_fields=True):
    """The vehicle's imperfections (spec/simulator.md, "Noise"), applied by noise.py:
    standard deviations, a probability and a blind zone, each default reasoned from the
    paper's vehicle. A world has them when it says `noise = true` or has a [noise]
    table; without either, or with `noise = false`, it has NOISELESS."""

    image_px: Annotated[float, _in(0, 100, "px", "on the centroid x and y, each IMG")] = 0.3
    image_area: Annotated[float, _in(0, 1, "1", "relative, on the area, each IMG")] = 0.03
    image_deg: Annotated[float, _in(0, 90, "deg", "on the axis angle, each IMG")] = 1.0
    line_cm: Annotated[float, _in(0, 100, "cm", "on the traced line's offset, each tick")] = 0.2
    line_deg: Annotated[float, _in(0, 90, "deg", "on the traced line's angle, each tick")] = 1.0
    ultrasonic_cm: Annotated[float, _in(0, 100, "cm", "on each distance echoed")] = 1.0
    ultrasonic_dropout: Annotated[float, _in(0, 1, "1", "chance a reading hears no echo")] = 0.02
    ultrasonic_blind: Annotated[float, _in(0, 100, "cm", "the nearest distance read")] = 5.0
    # A tenth at most for the relative errors: a wheel that ran backwards would need a
    # draw of ten standard deviations.
    odometry: Annotated[float, _in(0, 0.1, "1", "each wheel's scale error, once per run")] = 0.005
    slip: Annotated[float, _in(0, 10, "cm", "a wheel's slip over each metre it turns")] = 0.5
    wheel_speed: Annotated[float, _in(0, 0.1, "1", "each wheel's speed error, once per run")] = 0.01
    steering_deg: Annotated[float, _in(0, 10, "deg", "the steering's offset, once per run")] = 0.5
    start_cm: Annotated[float, _in(0, 100, "cm", "on the start's x and y")] = 1.0
    start_deg: Annotated[float, _in(0, 45, "deg", "on the start's heading")] = 1.0
    delay: Annotated[float, _in(0, 10, "s", "how late the camera and ultrasonic report")] = 0.0


NOISELESS = Noise(**dict.fromkeys(Noise.__struct_fields__, 0.0))
"""A world with no noise: every run is exact, whatever its seed."""


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


LED_SPACING = 6.0  # cm from the marker's upper LED down to its lower one (Fig. 3)
LED_RADIUS = 1.0  # cm
# How high what stands on the floor is, unless the world says (cm): what the camera sees
# over and what it does not.
STAND_HEIGHT = 80.0  # a workbench
WALL_HEIGHT = 200.0  # a room's wall, above any camera on the vehicle
OBSTACLE_HEIGHT = 100.0  # a crate, a person


@dataclass(frozen=True, slots=True)
class Stand:
    """A work stand: a rectangle centred on (x, y), `depth` along `facing` (degrees,
    the way its marker looks), `width` across, `height` high. Its marker sits in the
    middle of the face: two LEDs LED_SPACING apart vertically, the upper one at
    `marker_height` (None: the camera's height)."""

    name: str
    x: float
    y: float
    width: float
    depth: float
    facing: float
    height: float = STAND_HEIGHT
    marker_height: float | None = None

    def leds(self, camera_height: float) -> tuple[float, float]:
        """The heights of the marker's upper and lower LEDs' centres (cm)."""
        upper = camera_height if self.marker_height is None else self.marker_height
        return upper, upper - LED_SPACING

    def corners(self) -> list[Point]:
        return rectangle(self.x, self.y, self.depth, self.width, math.radians(self.facing))

    def marker(self) -> Point:
        """Where the marker is on the floor plan: the middle of the face."""
        heading = math.radians(self.facing)
        return (self.x + self.depth / 2 * math.cos(heading),
                self.y + self.depth / 2 * math.sin(heading))


@dataclass(frozen=True, slots=True)
class Block:
    """A wall or an obstacle (`kind`): a polygon the vehicle must not touch, `height` cm
    high. Its name is the world file's, or where it is ("at (795, 200)", `place`)."""

    name: str
    points: tuple[Point, ...]
    height: float = WALL_HEIGHT
    kind: str = "wall"  # or "obstacle": what the reports call it


@dataclass(frozen=True, slots=True)
class Scene:
    """A recognition set-up of the image processor: which features it sees (a kind,
    "lines", "marks" or "markers", or a feature's name) inside which window of the
    image (x0, y0, x1, y1 in pixels, end exclusive)."""

    sees: tuple[str, ...]
    window: tuple[int, int, int, int]


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
    noise: Noise = NOISELESS
    time_limit: float = 600.0  # s of simulated time before the run is stopped
    goal: Goal | None = None  # what the run must achieve ([goal]; vm/sim/goal.py)
    varied: tuple[Varied, ...] = ()  # what each run draws ([vary]; vm/sim/vary.py)

    def judge(self, start: Pose | None = None) -> Judge:
        """The judge of this world's goal for a run from `start` (by default the world's
        start). ValueError when the world has no goal."""
        if self.goal is None:
            raise ValueError("the world has no [goal] to judge a run by")
        if start is None:
            x, y, heading = self.start
            start = Pose(x, y, math.radians(heading))
        return Judge(self.goal, start, self.vehicle.camera_ahead)

    def parameter(self, key: str) -> Parameter:
        """The value `key` names (`start.x`, `stands.NAME.facing`, `vehicle.k1`,
        `noise.slip`) and its range; ValueError saying why when it names none."""
        table, name, field = split_key(key)
        if table == "start" and field in _START_FIELDS:
            index = _START_FIELDS.index(field)
            low, high = _float_range(StartTable, field)
            if index < 2:  # on the floor
                low, high = max(low, 0.0), min(high, self.floor[index])
            return Parameter(self.start[index], low, high)
        if table == "stands" and field in _STAND_FIELDS:
            # Of stands of one name, the last: the one a [[goal.hold]] at it holds at.
            stand = next((stand for stand in reversed(self.stands) if stand.name == name),
                         None)
            if stand is None:
                names = ", ".join(f'"{stand.name}"' for stand in self.stands)
                raise ValueError(f'no stand is named "{name}"; ' + (
                    f"name one of {names}" if names else "the world has no [[stands]]"))
            return Parameter(getattr(stand, field), *_float_range(StandTable, field))
        settings: Vehicle | Noise = self.vehicle if table == "vehicle" else self.noise
        if table in ("vehicle", "noise") and field in settings.__struct_fields__:
            if not isinstance(getattr(settings, field), float):
                raise ValueError("a whole number, which is never drawn nor swept; set "
                                 "it in the world")
            low, high = _float_range(type(settings), field)
            if field == "trace_interval":  # a run's ticks are bounded
                low = max(low, self.time_limit / MAX_TICKS)
            return Parameter(getattr(settings, field), low, high)
        fields = {"start": _START_FIELDS, "stands": _STAND_FIELDS}.get(
            table, tuple(name for name in settings.__struct_fields__
                         if isinstance(getattr(settings, name), float)))
        raise ValueError(unknown_key(field, fields))

    def moved(self, offsets: Mapping[str, float]) -> World:
        """This world with the parameters of `offsets` moved by them (cm, degrees, or the
        setting's unit), a hold's marker with its stand; ValueError when one would leave
        its range."""
        start = list(self.start)
        stands = list(self.stands)
        last = {stand.name: i for i, stand in enumerate(stands)}  # as parameter() finds it
        settings: dict[str, dict[str, float]] = {"vehicle": {}, "noise": {}}
        for key, offset in offsets.items():
            parameter = self.parameter(key)
            value = parameter.value + offset
            slack = 1e-9 * max(1.0, abs(parameter.low), abs(parameter.high))  # rounding
            if not parameter.low - slack <= value <= parameter.high + slack:
                raise ValueError(f"{key}: {parameter.value:g} moved by {offset:+g} is "
                                 f"{value:g}, outside {parameter.low:g}..{parameter.high:g}")
            value = min(parameter.high, max(parameter.low, value))
            table, name, field = split_key(key)
            if table == "start":
                start[_START_FIELDS.index(field)] = value
            elif name is not None:
                stand = stands[last[name]]
                x, y, facing = {"x": (value, stand.y, stand.facing),
                                "y": (stand.x, value, stand.facing),
                                "facing": (stand.x, stand.y, value)}[field]
                stands[last[name]] = dataclasses.replace(stand, x=x, y=y, facing=facing)
            else:
                settings[table][field] = value
        goal = self.goal
        if goal is not None:
            goal = dataclasses.replace(goal, holds=tuple(
                dataclasses.replace(hold, marker=stands[last[hold.stand]].marker())
                for hold in goal.holds))
        return dataclasses.replace(
            self, start=(start[0], start[1], start[2]), stands=tuple(stands),
            vehicle=msgspec.structs.replace(self.vehicle, **settings["vehicle"]),
            noise=msgspec.structs.replace(self.noise, **settings["noise"]), goal=goal)

    def drawn(self, seed: int) -> tuple[World, dict[str, float]]:
        """This world as the run of `seed` has it, each [vary] parameter drawn, and the
        values drawn (each parameter's value in the run)."""
        offsets = {}
        for varied in self.varied:
            parameter = self.parameter(varied.key)
            offsets[varied.key] = varied.distribution.draw(
                uniform_draw(seed, varied.key), parameter.low - parameter.value,
                parameter.high - parameter.value)
        world = self.moved(offsets)
        return world, {key: world.parameter(key).value for key in offsets}


_START_FIELDS = ("x", "y", "heading")
_STAND_FIELDS = ("x", "y", "facing")


@cache
def _float_range(schema: type[Struct], field: str) -> tuple[float, float]:
    """The range a number of the world file's `schema` may take."""
    struct = mi.type_info(schema)
    assert isinstance(struct, mi.StructType)
    info = next(info for info in struct.fields if info.encode_name == field)
    kind = info.type.type if isinstance(info.type, mi.Metadata) else info.type
    assert isinstance(kind, mi.FloatType) and kind.ge is not None and kind.le is not None
    return float(kind.ge), float(kind.le)  # a range of 0..10 is written in integers




# The file -------------------------------------------------------------------------------

MAX_TICKS = 2_000_000
"""The most ticks of the tracing timer a run may take (its time limit over the trace
interval): with the simulator's fixed step, this bounds the steps of any run."""

MAX_POINTS = 10_000
"""The most points in all lines and polygons together, each stand counting its four
corners: a floor of a few metres needs far fewer, and it bounds what loading and each
step of the simulation cost."""

FloorLength = Annotated[float, _in(10, _LIMIT, "cm", "the floor's extent")]
Pixel = Annotated[int, Meta(ge=0, le=1024)]


class FloorTable(Struct, forbid_unknown_fields=True):
    """The floor runs from (0, 0) to `size`, cm."""

    size: Annotated[tuple[FloorLength, FloorLength], Meta(extra={
        "expected": "[width, depth] in cm, e.g. size = [600, 400]"})]


class StartTable(Struct, forbid_unknown_fields=True):
    """Where the vehicle starts, and its heading."""

    x: Coordinate
    y: Coordinate
    heading: Angle = 0.0


class LineTable(Struct, forbid_unknown_fields=True, kw_only=True):
    """A guidance line: a polyline."""

    name: Name | UnsetType = UNSET
    points: Annotated[list[PointValue], Meta(min_length=2)]
    width: Annotated[float, _in(0.1, 1000, "cm", "the line's width")] = 2.0


class PolygonTable(Struct, forbid_unknown_fields=True, kw_only=True):
    """A mark on the floor, a wall or an obstacle: a polygon."""

    name: Name | UnsetType = UNSET
    points: Annotated[list[PointValue], Meta(min_length=3)]


Height = Annotated[float, _in(1, 1000, "cm", "its top above the floor")]


class WallTable(PolygonTable, kw_only=True):
    """A wall: a polygon the vehicle must not touch, which hides what is behind it."""

    height: Height = WALL_HEIGHT


class ObstacleTable(PolygonTable, kw_only=True):
    """An obstacle: a polygon the vehicle must not touch, which hides what is behind it."""

    height: Height = OBSTACLE_HEIGHT


class StandTable(Struct, forbid_unknown_fields=True, kw_only=True):
    """A work stand: a rectangle with a marker in the middle of the face it looks out
    of."""

    name: Name | UnsetType = UNSET
    x: Coordinate
    y: Coordinate
    width: Annotated[float, _in(1, 1000, "cm", "across the face")] = 40.0
    depth: Annotated[float, _in(1, 1000, "cm", "along facing")] = 40.0
    facing: Angle
    height: Height = STAND_HEIGHT
    marker_height: Annotated[float, _in(
        LED_SPACING + LED_RADIUS, 1000, "cm", "the upper LED's centre above the floor "
        "(default: the vehicle's camera_height)")] | UnsetType = UNSET


class SceneTable(Struct, forbid_unknown_fields=True, kw_only=True):
    """A recognition set-up of the image processor, selected by (SCN number)."""

    number: Annotated[int, Meta(ge=0, le=7)]
    sees: Annotated[list[Annotated[str, Meta(max_length=64)]], Meta(max_length=64, description=(
        'kinds ("lines", "marks", "markers") or names of lines, marks and stands'))]
    window: Annotated[tuple[Pixel, Pixel, Pixel, Pixel], Meta(extra={
        "expected": "[x0, y0, x1, y1] in pixels"})] = (0, 0, 1024, 1024)


class FuzzyTable(Struct, forbid_unknown_fields=True):
    """What (FZI) reads into s and t."""

    s: Int16 = 0
    t: Int16 = 0


class LimitsTable(Struct, forbid_unknown_fields=True):
    """What a run may ask for."""

    time: Annotated[float, _in(0.1, 86400, "s", "simulated time before the run is "
                               "stopped")] = 600.0


class GoalRegionTable(PolygonTable, kw_only=True):
    """A region of the goal: the vehicle's centre in the polygon, and, when `heading`
    is given, its heading within `tolerance` of it."""

    heading: Angle | UnsetType = UNSET
    tolerance: Annotated[float, _in(0, 180, "degrees", "from heading, either way")] = 10.0


class HoldTable(Struct, forbid_unknown_fields=True, kw_only=True):
    """Standing still with the camera near a stand's marker."""

    stand: Name
    within: Annotated[float, _in(1, 1000, "cm", "from the camera to the marker")] = 60.0
    seconds: Annotated[float, _in(0, 3600, "s", "standing still there, at least")] = 0.5


class GoalTable(Struct, forbid_unknown_fields=True, kw_only=True):
    """What the program must achieve (vm/sim/goal.py)."""

    reach: list[GoalRegionTable] = []
    hold: list[HoldTable] = []
    end: GoalRegionTable | UnsetType = UNSET
    avoid: list[PolygonTable] = []
    deadline: Annotated[float, _in(0.1, 86400, "s", "when the reaches and holds are "
                                   "met and the run has ended, at the latest")] | UnsetType = UNSET


class WorldFile(Struct, forbid_unknown_fields=True, kw_only=True):
    """A world file of `rl1c sim --world` (spec/simulator.md)."""

    floor: FloorTable
    start: StartTable
    vehicle: Vehicle = msgspec.field(default_factory=Vehicle)
    lines: list[LineTable] = []
    marks: list[PolygonTable] = []
    stands: list[StandTable] = []
    walls: list[WallTable] = []
    obstacles: list[ObstacleTable] = []
    scenes: list[SceneTable] = []
    ports: dict[PortName, Byte] = {}
    fuzzy: FuzzyTable = msgspec.field(default_factory=FuzzyTable)
    noise: Noise | bool = False  # true: Noise's defaults; false: NOISELESS
    limits: LimitsTable = msgspec.field(default_factory=LimitsTable)
    goal: GoalTable | UnsetType = UNSET
    vary: VaryTable = msgspec.field(default_factory=VaryTable)


def decode_world(data: bytes, name: str) -> World:
    """A World from the bytes of a world file; WorldError says what is wrong."""
    try:
        document, text = read_document(data, name, "toml")
    except ConfigError as error:
        if data.lstrip().startswith(b"{"):
            mistaken = ConfigError(name, None, "", WORLD.mistaken_for(SENSOR_SCRIPT))
            raise WorldError(str(mistaken)) from mistaken
        raise WorldError(str(error)) from error  # which rl1c places
    return parse_world(document, text, name)


def parse_world(document: dict[str, Any], text: str = "", name: str = "<world>") -> World:
    """A World from the data of a world file (its `text` gives the lines of messages)."""
    try:
        WORLD.refuse_other(document, name, SENSOR_SCRIPT)
        return _World(convert(document, WorldFile, name, text), text, name).build()
    except ConfigError as error:
        raise WorldError(str(error)) from error  # which rl1c places


def place(points: list[Point]) -> str:
    """Where a polygon is, as a name: the middle of its bounding box, to the cm."""
    xs, ys = [x for x, _ in points], [y for _, y in points]
    return f"at ({(min(xs) + max(xs)) / 2:.0f}, {(min(ys) + max(ys)) / 2:.0f})"


def _named(name: str | UnsetType, default: str) -> str:
    """A feature's name, or the one it gets by its place when the file gives none."""
    return default if isinstance(name, UnsetType) else name


class _World:
    """The checks that span fields (the start on the floor, the scenes' names, the
    world's size), and the World they give."""

    def __init__(self, file: WorldFile, text: str, name: str) -> None:
        self.file = file
        self.text = text
        self.name = name
        self.points = 0

    def fail(self, path: KeyPath, detail: str) -> ConfigError:
        return error_at(self.name, self.text, path, detail)

    def count(self, points: int, path: KeyPath) -> None:
        """Count `points` against MAX_POINTS for the whole world."""
        self.points += points
        if self.points > MAX_POINTS:
            raise self.fail(path, f"the world's lines, polygons and stands have more than "
                                  f"{MAX_POINTS} points (a stand counts its 4 corners); "
                                  "simplify them (a straight run needs only its two ends)")

    def build(self) -> World:
        file = self.file
        floor, start = file.floor.size, file.start
        if not (0 <= start.x <= floor[0] and 0 <= start.y <= floor[1]):
            raise self.fail(("start",), f"({start.x:g}, {start.y:g}) is off the floor, "
                                        f"which runs from (0, 0) to ({floor[0]:g}, "
                                        f"{floor[1]:g})")
        ticks = file.limits.time / file.vehicle.trace_interval
        if ticks > MAX_TICKS:
            raise self.fail(("limits", "time"), f"a run of {file.limits.time:g} s with a "
                            f"tracing tick every {file.vehicle.trace_interval:g} s takes "
                            f"{ticks:.3g} ticks, more than {MAX_TICKS:,}; shorten the time "
                            "limit or lengthen vehicle.trace_interval")
        lines = []
        for i, line in enumerate(file.lines):
            self.count(len(line.points), ("lines", i, "points"))
            lines.append(Line(_named(line.name, f"line{i}"), tuple(line.points), line.width))
        marks = []
        for i, mark in enumerate(file.marks):
            self.count(len(mark.points), ("marks", i, "points"))
            marks.append(Mark(_named(mark.name, f"mark{i}"), tuple(mark.points)))
        stands = []
        for i, stand in enumerate(file.stands):
            self.count(4, ("stands", i))
            stands.append(Stand(_named(stand.name, f"stand{i}"), stand.x, stand.y, stand.width,
                                stand.depth, stand.facing, stand.height,
                                None if isinstance(stand.marker_height, UnsetType)
                                else stand.marker_height))
        blocks = []
        kinds: tuple[tuple[str, Sequence[WallTable | ObstacleTable]], ...] = (
            ("walls", file.walls), ("obstacles", file.obstacles))
        for kind, polygons in kinds:
            for i, block in enumerate(polygons):
                self.count(len(block.points), (kind, i, "points"))
                blocks.append(Block(_named(block.name, place(block.points)),
                                    tuple(block.points), block.height, kind[:-1]))
        world = World(floor=floor, start=(start.x, start.y, start.heading),
                      vehicle=file.vehicle, lines=tuple(lines), marks=tuple(marks),
                      stands=tuple(stands), blocks=tuple(blocks), scenes=self.scenes(),
                      ports=self.ports(), fuzzy=(file.fuzzy.s, file.fuzzy.t),
                      noise=self.noise(), time_limit=file.limits.time,
                      goal=self.goal(stands))
        return dataclasses.replace(world, varied=self.varied(world))

    def varied(self, world: World) -> tuple[Varied, ...]:
        """The [vary] table's entries, each a parameter of `world` whose draws stay
        within its range."""
        found = []
        for path, entry in entries(self.file.vary):
            where: KeyPath = ("vary", *path)
            try:
                spread = distribution(entry)
            except ValueError as error:
                raise self.fail((*where, wrong_key(error)) if wrong_key(error) else where,
                                str(error)) from None
            try:
                parameter = world.parameter(key_of(path))
            except ValueError as error:
                raise self.fail(where, str(error)) from None
            problem = check_bounds(spread, parameter.low - parameter.value,
                                   parameter.high - parameter.value)
            if problem is not None:
                raise self.fail(where, problem)
            found.append(Varied(key_of(path), spread))
        return tuple(found)

    def noise(self) -> Noise:
        match self.file.noise:
            case Noise() as noise:
                return noise
            case True:
                return Noise()
        return NOISELESS

    def goal(self, stands: list[Stand]) -> Goal | None:
        table = self.file.goal
        if isinstance(table, UnsetType):
            return None
        if not (table.reach or table.hold or table.avoid or not isinstance(table.end, UnsetType)
                or not isinstance(table.deadline, UnsetType)):
            raise self.fail(("goal",), "the goal asks for nothing; give it [[goal.reach]], "
                                       "[[goal.hold]], [goal.end], [[goal.avoid]] or a deadline")

        def region(path: KeyPath, table: PolygonTable, default: str) -> Region:
            self.count(len(table.points), (*path, "points"))
            if not isinstance(table, GoalRegionTable) or isinstance(table.heading, UnsetType):
                return Region(_named(table.name, default), tuple(table.points))
            return Region(_named(table.name, default), tuple(table.points),
                          math.radians(table.heading), math.radians(table.tolerance))

        markers = {stand.name: stand.marker() for stand in stands}
        holds = []
        for i, hold in enumerate(table.hold):
            if hold.stand not in markers:
                names = ", ".join(f'"{name}"' for name in markers)
                raise self.fail(("goal", "hold", i, "stand"), f'"{hold.stand}" is not the '
                                "name of a stand; " + (f"name one of {names}" if names else
                                                       "the world has no [[stands]]"))
            holds.append(Hold(hold.stand, markers[hold.stand], hold.within, hold.seconds))
        return Goal(
            reach=tuple(region(("goal", "reach", i), reach, f"reach{i}")
                        for i, reach in enumerate(table.reach)),
            holds=tuple(holds),
            end=None if isinstance(table.end, UnsetType) else region(("goal", "end"),
                                                                      table.end, "end"),
            avoid=tuple(region(("goal", "avoid", i), avoid, f"avoid{i}")
                        for i, avoid in enumerate(table.avoid)),
            deadline=None if isinstance(table.deadline, UnsetType) else table.deadline)

    def scenes(self) -> dict[int, Scene]:
        file = self.file
        named = [*(line.name for line in file.lines), *(mark.name for mark in file.marks),
                 *(stand.name for stand in file.stands)]
        known = {"lines", "marks", "markers", *(name for name in named if isinstance(name, str))}
        scenes: dict[int, Scene] = {}
        for i, scene in enumerate(file.scenes):
            if scene.number in scenes:
                raise self.fail(("scenes", i, "number"), f"scene {scene.number} is defined "
                                "twice; give each [[scenes]] its own number")
            x0, y0, x1, y1 = scene.window
            if x1 <= x0 or y1 <= y0:
                raise self.fail(("scenes", i, "window"), f"[{x0}, {y0}, {x1}, {y1}] is no "
                                "window: write [x0, y0, x1, y1], its left, top, right and "
                                "bottom edges in pixels, with x0 < x1 and y0 < y1")
            for j, seen in enumerate(scene.sees):
                if seen not in known:
                    raise self.fail(("scenes", i, "sees", j), f'"{seen}" is not a kind '
                                    '("lines", "marks", "markers") nor the name of a line, '
                                    "mark or stand")
            scenes[scene.number] = Scene(tuple(scene.sees), scene.window)
        return scenes

    def ports(self) -> dict[int, int]:
        ports = {}
        for key, data in self.file.ports.items():
            port = int(key)
            if not INPUT_PORTS.low <= port <= INPUT_PORTS.high:
                raise self.fail(("ports", key), f"{port} is outside {INPUT_PORTS.low}.."
                                                f"{INPUT_PORTS.high}, the input ports")
            ports[port] = data
        return ports
