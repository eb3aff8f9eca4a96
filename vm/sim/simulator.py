"""The physics of a simulated run (spec/simulator.md): the vehicle's state, the clock
that advances it in fixed steps, the tracing timer, the safety checks, and the record
of the run (the pose track, bounded by track.py, and events) that the pictures draw.

This module knows nothing of the Device protocol: device.py adapts it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

from . import camera, tracing, ultrasonic
from .geometry import Point, overlap, rectangle
from .motion import Odometer, Pose, advance, count, heading_degrees, time_to_cover
from .noise import Imperfections
from .track import History, Track
from .world import Scene, World

Command = Literal["MOV", "MVI"]
DEFAULT_STEP = 0.05  # s between two safety checks; the tracing timer has its own interval
_EMPTY_SCENE = Scene((), (0, 0, 1, 1))
MAX_EVENTS = 10_000
"""Lost lines, found lines and handlers taken that a run records (a fault and the end
are always recorded): more are counted in `events_left_out`."""


class SafetyFault(Exception):
    """The run was stopped: the vehicle left the floor, hit something, or ran out of
    time. `kind`, `time` and `pose` say which, when and where."""

    def __init__(self, kind: str, message: str, time: float, pose: Pose) -> None:
        super().__init__(f"{message} at {time:.2f} s, the vehicle at "
                         f"({pose.x:.1f}, {pose.y:.1f}) cm heading "
                         f"{heading_degrees(pose.heading, 1):.1f} degrees")
        self.kind = kind
        self.time = time
        self.pose = pose


@dataclass(frozen=True, slots=True)
class Event:
    """Something the picture marks: a lost or found line, a fault, the end."""

    time: float
    kind: str
    text: str
    pose: Pose


@dataclass(slots=True)
class _Motion:
    command: Command
    left: int  # the commanded wheel speeds, units
    right: int
    remaining: float = math.inf  # cm the centre still has to cover (MVI)


@dataclass(slots=True)
class Simulator:
    world: World
    step: float = DEFAULT_STEP
    seed: int = 0
    time: float = 0.0
    pose: Pose = field(init=False)
    steering: float = 0.0  # radians, + left
    motion: _Motion | None = None
    mode: int = 0
    lost: bool = False  # the line is out of view while tracing
    pan: int = camera.PULSES // 2
    tilted_down: bool = False
    scene: int = 0
    odometer: Odometer = field(default_factory=Odometer)
    track: list[tuple[float, Pose]] = field(init=False)  # decimated: track.py
    events: list[Event] = field(default_factory=list)
    events_left_out: int = 0
    _speeds: tuple[float, float] = (0.0, 0.0)  # the wheels' speeds now, units
    _tick: int = 1  # the tracing timer's next tick
    _noise: Imperfections = field(init=False)
    _obstacles: list[tuple[str, list[Point], Point, float]] = field(init=False)
    _lines: tracing.LineIndex = field(init=False)
    _echoes: ultrasonic.Echoes = field(init=False)
    _sceneries: dict[int, camera.Scenery] = field(default_factory=dict)  # built when used
    _reach: float = field(init=False)  # from the centre to the outline's corners
    _track: Track = field(init=False)
    _history: History | None = field(init=False)  # the recent poses, with a sensor delay
    on_move: Callable[[float, float, Pose, Pose], None] | None = None
    """Told each step exactly (its start and end times, the poses before and after),
    for what the decimated track cannot tell: the goal's judgement (goal.py)."""

    def __post_init__(self) -> None:
        x, y, heading = self.world.start
        self._noise = Imperfections(self.world.noise, self.seed)
        self.pose = self._noise.start(Pose(x, y, math.radians(heading)))
        self._track = Track(self.pose)
        self.track = self._track.points
        self._history = History(self.pose) if self.world.noise.delay else None
        self._lines = tracing.LineIndex(self.world.lines)
        self._obstacles = []
        for name, points in [(f"the stand {s.name}", s.corners()) for s in self.world.stands] + [
                (f"the {b.kind} {b.name}", list(b.points)) for b in self.world.blocks]:
            cx = sum(p[0] for p in points) / len(points)
            cy = sum(p[1] for p in points) / len(points)
            radius = max(math.hypot(p[0] - cx, p[1] - cy) for p in points)
            self._obstacles.append((name, points, (cx, cy), radius))
        self._echoes = ultrasonic.Echoes([points for _, points, _, _ in self._obstacles])
        self._reach = math.hypot(self.world.vehicle.length, self.world.vehicle.width) / 2

    # Commands, in physical terms ---------------------------------------------------------

    def drive(self, command: Command, left: int, right: int, cm: float = math.inf) -> None:
        """Set the wheel speeds (units); an MVI also the distance its centre covers."""
        self.motion = _Motion(command, left, right, abs(cm)) if (left or right) else None
        self._speeds = (float(left), float(right)) if self.motion else (0.0, 0.0)
        self.lost = False

    def halt(self) -> None:
        self.motion = None
        self._speeds = (0.0, 0.0)

    @property
    def wheel_speeds(self) -> tuple[float, float]:
        """The wheels' speeds now (units, left and right), as tracing corrects them."""
        return self._speeds

    def turn_steering(self, radians: float) -> float:
        """Set the steering; the seconds the steering motor takes."""
        delta = abs(radians - self.steering)
        self.steering = radians
        return math.degrees(delta) / self.world.vehicle.steer_rate

    def rotate(self, degrees: int) -> None:
        """Turn on the spot (PWS) by `degrees`, + left, stopping any motion first."""
        self.halt()
        vehicle = self.world.vehicle
        speed = vehicle.rotate_speed * (1 if degrees > 0 else -1)
        self._speeds = (-float(speed), float(speed))
        seconds = math.radians(abs(degrees)) * vehicle.tread / 2 / (
            vehicle.rotate_speed * vehicle.wheel_unit)
        self.run_for(seconds, interruptible=False)
        self._speeds = (0.0, 0.0)

    def pan_to(self, pulse: int) -> float:
        """Pan the camera; the seconds the pan motor takes."""
        delta = abs(pulse - self.pan) * 180 / camera.PULSES
        self.pan = pulse
        return delta / self.world.vehicle.pan_rate

    # Sensing -------------------------------------------------------------------------------

    def sensed_pose(self) -> Pose:
        """The pose the sensors report on: the present one, or the one `noise.delay`
        seconds ago (the last recorded at or before then)."""
        if self._history is None:
            return self.pose
        return self._history.at(self.time - self.world.noise.delay)

    def view(self) -> camera.View:
        tilt = math.radians(self.world.vehicle.tilt_down) if self.tilted_down else 0.0
        pose = self.sensed_pose()
        return camera.view_of(pose.x, pose.y, pose.heading, self.pan, tilt, self.world.vehicle)

    def image(self, view: camera.View | None = None) -> camera.Moments:
        """What the image processor measures now, in the selected scene; `view` is
        self.view(), when the caller has it already."""
        scenery = self._sceneries.get(self.scene)
        if scenery is None:
            scene = self.world.scenes.get(self.scene, _EMPTY_SCENE)
            scenery = self._sceneries[self.scene] = camera.Scenery(self.world, scene)
        return self._noise.image(camera.moments(*scenery.render(view or self.view())),
                                 scenery.window)

    def line_view(self) -> tracing.LineView | None:
        view = self.view()
        centre = camera.view_centre(view)
        if centre is None:
            return None
        cx, cy, slant = centre
        half = slant * math.tan(math.radians(self.world.vehicle.camera_fov) / 2)
        return self._noise.line(tracing.measure(self._lines, cx, cy, view.yaw, half))

    def range_to(self, sensor: str) -> float:
        vehicle = self.world.vehicle
        distance = ultrasonic.sense(sensor, self.sensed_pose(), vehicle.length, vehicle.width,
                                    vehicle.ultrasonic_cone, vehicle.ultrasonic_range,
                                    self._echoes)
        return self._noise.ultrasonic(distance, vehicle.ultrasonic_range)

    def distance(self) -> tuple[float, float, float]:
        """The counters: centre, right wheel, left wheel, in cm."""
        odometer = self.odometer
        return odometer.centre, odometer.right, odometer.left

    # The clock ----------------------------------------------------------------------------

    def run_for(self, seconds: float, interruptible: bool) -> Command | None:
        """Let `seconds` pass (math.inf: until a foreground MVI ends). Returns the command
        during which the line was lost, when the program must hear of it, whatever the
        wait (spec/language.md 7.7: the loss is taken after the call); an `interruptible`
        wait (TIM, MVI) then ends at once, any other runs to its end. Raises SafetyFault."""
        end = self.time + seconds
        foreground = self.motion is not None and self.motion.command == "MVI"
        vehicle = self.world.vehicle
        unit, interval, wheels = vehicle.wheel_unit, vehicle.trace_interval, self._noise.wheels
        heard: Command | None = None  # the loss the program is to hear of
        while self.time < end:
            motion = self.motion
            if foreground and motion is None:
                return heard
            speeds = self._speeds
            if speeds == (0.0, 0.0):  # standing
                if math.isinf(end):
                    return heard
                self.time = end
                self._check_time()
                return heard
            now = self.time
            if self._tick * interval < now:  # the timer ticked on while standing
                self._tick = math.floor(now / interval) + 1
            tick_time = self._tick * interval
            until = min(end, now + self.step, tick_time)
            left, right = wheels(speeds[0] * unit, speeds[1] * unit)
            if motion is not None and motion.command == "MVI":
                until = min(until, now + time_to_cover(motion.remaining, left, right))
            self._move(until - now, left, right)
            self.time = until
            self._check_safety()
            motion = self.motion
            if (motion is not None and motion.command == "MVI"
                    and motion.remaining <= 1e-6):  # 10 nm: well above rounding
                self.halt()
                continue
            if until >= tick_time:
                self._tick += 1
                lost = self._trace()
                if lost is not None and interruptible:
                    return lost
                heard = heard or lost
        return heard

    def _move(self, seconds: float, left: float, right: float) -> None:
        noise, before, start = self._noise, self.pose, self.time
        end = start + seconds
        on_floor = noise.ground(left, right, seconds)  # what the counters do not see
        after = self.pose = advance(before, self.steering + noise.steering, *on_floor,
                                    self.world.vehicle.tread, seconds)
        count(self.odometer, left, right, seconds)
        motion = self.motion
        if motion is not None and motion.command == "MVI":
            motion.remaining -= abs(left + right) / 2 * seconds
        self._track.add(end, after)
        if self._history is not None:
            self._history.add(end, after)
        if self.on_move is not None:
            self.on_move(start, end, before, after)

    def _trace(self) -> Command | None:
        """One tick of the tracing timer; the command the line was lost during, when the
        program is to hear of it (modes 2 and 3)."""
        motion = self.motion
        if motion is None or self.mode == 0:
            return None
        seen = self.line_view()
        if seen is not None:
            if self.lost:
                self.lost = False
                self.note("found", "line found")
            vehicle = self.world.vehicle
            self._speeds = tracing.correct(motion.left, motion.right, seen, vehicle.k1,
                                           vehicle.k2)
            return None
        self._speeds = (float(motion.left), float(motion.right))  # straight on, uncorrected
        if self.lost:
            return None
        self.lost = True
        self.note("lost", f"line lost during {motion.command} in mode {self.mode}")
        if self.mode == 1:
            return None
        if self.mode == 2:
            self.halt()
        return motion.command

    def note(self, kind: str, text: str) -> None:
        """Record an event at the present time and pose, for the pictures."""
        if len(self.events) >= MAX_EVENTS and kind not in ("fault", "end"):
            self.events_left_out += 1
            return
        self.events.append(Event(self.time, kind, text, self.pose))

    # Safety -------------------------------------------------------------------------------

    def outline(self) -> list[Point]:
        vehicle = self.world.vehicle
        return rectangle(self.pose.x, self.pose.y, vehicle.length, vehicle.width,
                         self.pose.heading)

    def _check_time(self) -> None:
        if self.time > self.world.time_limit:
            self._stop("time-limit", f"the run passed its time limit of "
                                     f"{self.world.time_limit:g} s")

    def _check_safety(self) -> None:
        if self.time > self.world.time_limit:
            self._check_time()
        x, y = self.pose.x, self.pose.y
        reach = self._reach
        near = [(name, points) for name, points, (cx, cy), radius in self._obstacles
                if math.hypot(cx - x, cy - y) <= radius + reach]
        width, depth = self.world.floor
        if not near and reach < x < width - reach and reach < y < depth - reach:
            return  # the outline cannot reach an edge or an obstacle: no need to draw it
        corners = self.outline()
        for cx, cy in corners:
            if not (0 <= cx <= width and 0 <= cy <= depth):
                self._stop("off-floor", f"the vehicle left the floor at corner "
                                        f"({cx:.1f}, {cy:.1f})")
        for name, points in near:
            if overlap(corners, points):
                self._stop("collision", f"the vehicle hit {name}")

    def _stop(self, kind: str, message: str) -> None:
        self.halt()
        self.note("fault", message)
        raise SafetyFault(kind, message, self.time, self.pose)
