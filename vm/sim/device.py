"""The Device adapter: today's blocking Device protocol (vm/device.py) over the
simulator's physics. Each method turns one built-in into a physical command, lets the
simulated time it takes pass, and records the call with the vehicle's pose in `trace`.

Simulated time passes in the calls, and between them at `vehicle.instruction_time` for
each instruction the engine ran (`count_instructions`, `catch_up`): every call first lets
the time of the instructions since the last one pass.

A safety fault (off the floor, a collision, the time limit) surfaces as a DeviceError
from the call during which it happened, or from `catch_up` between calls, so the engine
stops the vehicle and reports the source line; `fault` keeps its details.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from rl1.vm.device import DeviceError, FuzzyReading, ImageReading, LineLost, Odometry
from rl1.vm.language import LOST_LINE_RULES

from .camera import PULSES
from .motion import Pose, heading_degrees
from .sightings import Sighting, Sightings
from .simulator import SafetyFault, Simulator
from .world import World

_PULSES_PER_DEGREE = PULSES / 180  # pulses per degree of pan


def _no_instructions() -> int:
    return 0


def _int16(value: float) -> int:
    return max(-32768, min(32767, round(value)))


@dataclass(frozen=True, slots=True)
class SimEntry:
    """One command the device received at simulated time `time` (s), from source line
    `line` (None: unknown), with the pose the vehicle had when it was done."""

    time: float
    call: str
    args: tuple[int, ...]
    result: tuple[int, ...] | None
    pose: Pose
    line: int | None = None

    def to_json(self) -> dict[str, Any]:
        entry: dict[str, Any] = {
            "time": round(self.time, 4), "call": self.call, "args": list(self.args),
            "pose": [round(self.pose.x, 2), round(self.pose.y, 2),
                     heading_degrees(self.pose.heading, 2)],
            "line": self.line}
        if self.result is not None:
            entry["result"] = list(self.result)
        return entry


@dataclass(frozen=True, slots=True)
class RunOn:
    """What the vehicle did after the program ended with it moving ((END) leaves motion
    in effect): it ran on for `seconds` until `stop` stopped it (a safety stop, the time
    limit included), or until it stopped by itself (`stop` None: a lost line in mode 2)."""

    seconds: float
    stop: SafetyFault | None


class SimDevice:
    """A Device that drives the simulated vehicle in `world`."""

    def __init__(self, world: World, seed: int = 0, step: float | None = None) -> None:
        self.sim = Simulator(world, seed=seed) if step is None else Simulator(
            world, step=step, seed=seed)
        self.trace: list[SimEntry] = []
        self.sightings = Sightings()  # what each (IMG) saw, for the pictures
        self.pending: LineLost | None = None
        self.fault: SafetyFault | None = None
        self.line: int | None = None  # the engine's source line (Device.line)
        self._executed: Callable[[], int] = _no_instructions  # count_instructions
        self._charged = 0  # the instructions whose time has passed

    # The interpreter's time

    def count_instructions(self, executed: Callable[[], int]) -> None:
        """Let `vehicle.instruction_time` pass for each instruction `executed()` counts
        (the VM's instructions, the interpreter's statements), from now on."""
        self._executed = executed
        self._charged = executed()

    @property
    def slice(self) -> int:
        """Instructions whose time is one step of the simulator: how far an engine is
        stepped between two `catch_up`s when the program makes no call."""
        return max(1, round(self.sim.step / self.sim.world.vehicle.instruction_time))

    def catch_up(self) -> None:
        """Let the time of the instructions run since the last call pass; a loss of the
        line meanwhile is pending. Raises DeviceError on a safety stop."""
        executed = self._executed()
        if executed > self._charged:
            seconds = (executed - self._charged) * self.sim.world.vehicle.instruction_time
            self._charged = executed
            self._pass(seconds)

    # Bookkeeping

    def _record(self, call: str, *args: int, result: tuple[int, ...] | None = None,
                start: float | None = None) -> None:
        """Record a call done now that started at `start` (None: now, a call that took
        no time): a trace gives the time each call was made, as the scripted device's."""
        self.trace.append(SimEntry(self.sim.time if start is None else start, call, args,
                                   result, self.sim.pose, self.line))

    def _begin(self) -> None:
        """The start of every call: the instructions before it take their time."""
        self.catch_up()
        self._refuse_after_fault()

    def _refuse_after_fault(self) -> None:
        if self.fault is not None:
            raise DeviceError(f"the simulation was stopped: {self.fault}")

    def _pass(self, seconds: float, interruptible: bool = False) -> None:
        self._refuse_after_fault()
        try:
            lost = self.sim.run_for(seconds, interruptible)
        except SafetyFault as fault:
            self.fault = fault
            raise DeviceError(f"safety stop [{fault.kind}]: {fault}") from None
        if lost is not None and self.pending is None:
            self.pending = LineLost(lost, self.sim.mode)

    def _after(self, call: str, seconds: float, *args: int) -> None:
        """A call of fixed duration, whose `seconds` were set when it began."""
        start = self.sim.time
        self._pass(seconds)
        self._record(call, *args, start=start)

    # Motion and steering

    def free(self) -> None:
        self._begin()
        self.sim.halt()
        self._record("FRE")

    def hold(self) -> None:
        self._begin()
        self.sim.halt()
        self._record("HLD")

    def steering_origin(self) -> None:
        self._begin()
        self._after("ORG", self.sim.turn_steering(0.0))

    def move_distance(self, left: int, right: int, cm: int) -> None:
        self._begin()
        if cm != 0 and left + right == 0:
            raise DeviceError(f"(MVI {left},{right},{cm}) would never end: with wheel speeds "
                              f"{left} and {right} the vehicle's centre does not move")
        # The sign of cm is taken from the wheels: a distance is covered, either way.
        start = self.sim.time
        self.sim.drive("MVI", left, right, cm)
        if cm != 0:
            self._pass(math.inf, interruptible=True)
        else:
            self.sim.halt()
        self._record("MVI", left, right, cm, start=start)

    def move(self, left: int, right: int) -> None:
        self._begin()
        self.sim.drive("MOV", left, right)
        self._record("MOV", left, right)

    def steer_right(self, degrees: int) -> None:
        self._begin()
        self._after("STR", self.sim.turn_steering(self.sim.steering - math.radians(degrees)),
                    degrees)

    def steer_left(self, degrees: int) -> None:
        self._begin()
        self._after("STL", self.sim.turn_steering(self.sim.steering + math.radians(degrees)),
                    degrees)

    def steer_by(self, tenths: int) -> None:
        self._begin()
        self._after("STX", self.sim.turn_steering(self.sim.steering + math.radians(tenths / 10)),
                    tenths)

    def rotate(self, degrees: int) -> None:
        self._begin()
        start = self.sim.time
        try:
            self.sim.rotate(degrees)
        except SafetyFault as fault:
            self.fault = fault
            raise DeviceError(f"safety stop [{fault.kind}]: {fault}") from None
        self._record("ROT", degrees, start=start)

    def set_tracing(self, mode: int) -> None:
        self._begin()
        self.sim.mode = mode
        self._record("TRC", mode)

    def wait(self, tenths: int) -> None:
        self._begin()
        start = self.sim.time
        self._pass(tenths / 10, interruptible=True)
        self._record("TIM", tenths, start=start)

    # Sensing, camera, I/O, fuzzy board

    def clear_distance(self) -> None:
        self._begin()
        self.sim.odometer.centre = self.sim.odometer.right = self.sim.odometer.left = 0.0
        self._record("KYC")

    def read_distance(self) -> Odometry:
        self._begin()
        centre, right, left = (_int16(v) for v in self.sim.distance())
        self._record("KYO", result=(centre, right, left))
        return Odometry(centre, right, left)

    def select_scene(self, scene: int) -> None:
        self._begin()
        self.sim.scene = scene
        self._record("SCN", scene)

    def measure_image(self) -> ImageReading:
        self._begin()
        start = self.sim.time
        self._pass(self.sim.world.vehicle.image_time)
        view = self.sim.view()
        found = self.sim.image(view)
        reading = ImageReading(found.area if found.area <= 32767 else 32767,
                               _int16(found.x), _int16(found.y), _int16(found.angle))
        self._record("IMG", result=(reading.area, reading.x, reading.y, reading.z),
                     start=start)
        self.sightings.add(Sighting(start, self.sim.scene, view,
                                    (reading.area, reading.x, reading.y)))
        return reading

    def camera_origin(self) -> None:
        self._begin()
        seconds = self.sim.pan_to(PULSES // 2)
        self.sim.tilted_down = False
        self._after("CAM Z", max(seconds, self.sim.world.vehicle.tilt_time))

    def camera_up(self) -> None:
        self._begin()
        self.sim.tilted_down = False
        self._after("CAM U", self.sim.world.vehicle.tilt_time)

    def camera_down(self) -> None:
        self._begin()
        self.sim.tilted_down = True
        self._after("CAM D", self.sim.world.vehicle.tilt_time)

    def camera_pan_angle(self, degrees: int) -> None:
        self._begin()
        self._after("CAM A", self.sim.pan_to(round(degrees * _PULSES_PER_DEGREE)), degrees)

    def camera_pan_pulse(self, pulse: int) -> None:
        self._begin()
        self._after("CAM P", self.sim.pan_to(pulse), pulse)

    def camera_position(self) -> int:
        self._begin()
        self._record("CAM R", result=(self.sim.pan,))
        return self.sim.pan

    def ultrasonic(self, sensor: str) -> int:
        self._begin()
        start = self.sim.time
        self._pass(self.sim.world.vehicle.ultrasonic_time)
        distance = _int16(self.sim.range_to(sensor))
        self._record(f"ULT {sensor}", result=(distance,), start=start)
        return distance

    def lamp(self, on: int) -> None:
        self._begin()
        self._record("LMP", on)

    def read_port(self, port: int) -> int:
        self._begin()
        data = self.sim.world.ports.get(port, 0)
        self._record("INP", port, result=(data,))
        return data

    def write_port(self, port: int, data: int) -> None:
        self._begin()
        self._record("OUT", port, data)

    def fuzzy_write(self, a: int, b: int) -> None:
        self._begin()
        self._record("FZO", a, b)

    def fuzzy_read(self) -> FuzzyReading:
        self._begin()
        s, t = self.sim.world.fuzzy
        self._record("FZI", result=(s, t))
        return FuzzyReading(s, t)

    # After the program

    def run_on(self) -> RunOn | None:
        """Let the world run on after the program ended with the vehicle moving, until
        it stops: what it did, or None when it was standing (or had faulted)."""
        if self.sim.motion is None or self.fault is not None:
            return None
        started = self.sim.time
        try:
            self.sim.run_for(math.inf, interruptible=False)
        except SafetyFault as fault:
            return RunOn(self.sim.time - started, fault)
        self.sim.note("end", "the vehicle stopped")
        return RunOn(self.sim.time - started, None)

    # Engine services

    def stop(self) -> None:
        self.sim.halt()
        self._record("STOP")

    def poll_event(self) -> LineLost | None:
        event, self.pending = self.pending, None
        if event is not None:
            label = next((rule.label for rule in LOST_LINE_RULES
                          if (rule.mode, rule.command) == (event.mode, event.command)), None)
            self.sim.note("handler", f"the program takes the lost line: jump to :{label}")
        return event
