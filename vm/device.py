"""The DEVICE interface: what an RL/I program drives, as seen by the interpreter and the VM.

A `Device` has one method per built-in form. The engine (interpreter or VM) evaluates and
range-checks the arguments, calls the method, and stores what a sensing method returns
into R and the reserved variables; the device never touches program state.

Time belongs to the device. Waiting methods (`wait`, `move_distance`, and the other
built-ins that `language.Builtin.waits` marks) return when the device's clock says the
command is done; `move` returns at once.

Division of work for a lost guidance line (Table 4):
- The device knows the tracing mode (`set_tracing`) and does the physical part: mode 0
  no tracing (nothing is lost); mode 1 it goes straight until it finds the line, and the
  program never hears of it; mode 2 it stops the vehicle (and aborts an MVI); mode 3 it
  keeps the motion going (an MVI carries on in the background).
- In modes 2 and 3, while motion is in effect (a non-zero MOV, or an MVI in progress),
  it then holds a `LineLost` for the program; a `wait` or `move_distance` in progress
  returns early so that the program gets it promptly.
- The engine takes the event between instructions (`poll_event`; `pending` lets it look
  without a call where speed matters) and decides the jump
  target from the event's mode and command: :98/:99 for mode 2 during MOV/MVI, :96/:97
  for mode 3. A target the program does not define is a run-time fault.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, Protocol

from .language import BUILTINS

MotionCommand = Literal["MOV", "MVI"]


class DeviceError(Exception):
    """The device failed or refused a command; the message says what and why."""


@dataclass(frozen=True, slots=True)
class LineLost:
    """The guidance line was lost while `command` was in effect, in tracing `mode`."""

    command: MotionCommand
    mode: int


@dataclass(frozen=True, slots=True)
class ImageReading:
    """What (IMG) measures: area in pixels (into w), centroid x, y (pixels), angle z."""

    area: int
    x: int
    y: int
    z: int


@dataclass(frozen=True, slots=True)
class Odometry:
    """What (KYO) reads: the vehicle centre's movement (the result), the right wheel's
    (into u) and the left wheel's (into v)."""

    centre: int
    right: int
    left: int


@dataclass(frozen=True, slots=True)
class FuzzyReading:
    """What (FZI) reads from the fuzzy-logic board, into s and t."""

    s: int
    t: int


READING_NAMES: dict[str, tuple[str, ...]] = {
    "IMG": ("area", "x", "y", "angle"),
    "KYO": ("centre", "right", "left"),
    "FZI": ("s", "t"),
}
"""What each value of a reading of several values is, in order, as reports name them."""


class Device(Protocol):
    """A vehicle. Arguments arrive already range-checked against language.py; values
    returned must be 16-bit signed integers. Any method may raise DeviceError."""

    # Motion and steering (Table 2)
    def free(self) -> None: ...  # (FRE): also stops the vehicle
    def hold(self) -> None: ...  # (HLD): also stops the vehicle
    def steering_origin(self) -> None: ...  # (ORG)
    def move_distance(self, left: int, right: int, cm: int) -> None: ...  # (MVI)
    def move(self, left: int, right: int) -> None: ...  # (MOV): returns at once
    def steer_right(self, degrees: int) -> None: ...  # (STR)
    def steer_left(self, degrees: int) -> None: ...  # (STL)
    def steer_by(self, tenths: int) -> None: ...  # (STX)
    def rotate(self, degrees: int) -> None: ...  # (ROT)
    def set_tracing(self, mode: int) -> None: ...  # (TRC)
    def wait(self, tenths: int) -> None: ...  # (TIM)

    # Sensing, camera, I/O and the fuzzy board (Table 3)
    def clear_distance(self) -> None: ...  # (KYC)
    def read_distance(self) -> Odometry: ...  # (KYO)
    def select_scene(self, scene: int) -> None: ...  # (SCN)
    def measure_image(self) -> ImageReading: ...  # (IMG)
    def camera_origin(self) -> None: ...  # (CAM Z)
    def camera_up(self) -> None: ...  # (CAM U)
    def camera_down(self) -> None: ...  # (CAM D)
    def camera_pan_angle(self, degrees: int) -> None: ...  # (CAM A)
    def camera_pan_pulse(self, pulse: int) -> None: ...  # (CAM P)
    def camera_position(self) -> int: ...  # (CAM R)
    def ultrasonic(self, sensor: str) -> int: ...  # (ULT A) .. (ULT D)
    def lamp(self, on: int) -> None: ...  # (LMP)
    def read_port(self, port: int) -> int: ...  # (INP)
    def write_port(self, port: int, data: int) -> None: ...  # (OUT)
    def fuzzy_write(self, a: int, b: int) -> None: ...  # (FZO)
    def fuzzy_read(self) -> FuzzyReading: ...  # (FZI)

    # Engine services
    def stop(self) -> None:
        """Stop the vehicle at once; the engine calls this first on any fault."""

    pending: LineLost | None
    """The lost-line event waiting to be taken, if any; reading it takes nothing."""

    line: int | None
    """The source line the engine is running (None when unknown: code without a line
    map): the engine's adapter (`perform`, `hardware.Blocking`) sets it before each call
    and `stop`, so that what the device records says where it came from."""

    def poll_event(self) -> LineLost | None:
        """The pending lost-line event, if any, removing it."""


@dataclass(frozen=True, slots=True)
class Outcome:
    """What a built-in call gives the program: its result (None if it has none) and the
    values of the reserved variables it writes, in the order of `Form.writes`."""

    result: int | None
    writes: tuple[int, ...] = ()


NOTHING = Outcome(None)


def _effect(action: Callable[[], None]) -> Outcome:
    action()
    return NOTHING


def _value(value: int) -> Outcome:
    return Outcome(value)


def _image(reading: ImageReading) -> Outcome:
    return Outcome(reading.area, (reading.area, reading.x, reading.y, reading.z))


def _odometry(reading: Odometry) -> Outcome:
    return Outcome(reading.centre, (reading.right, reading.left))


def _fuzzy(reading: FuzzyReading) -> Outcome:
    return Outcome(None, (reading.s, reading.t))


FormKey = tuple[str, str | None]
"""A built-in form as (mnemonic, selector): ("MOV", None), ("CAM", "A")."""

Binding = Callable[[Device, tuple[int, ...]], Outcome]

# Each built-in form (mnemonic, selector) bound to its Device method. Both engines call
# devices through this one table, so a form means the same device action in both.
BINDINGS: dict[FormKey, Binding] = {
    ("FRE", None): lambda d, a: _effect(d.free),
    ("HLD", None): lambda d, a: _effect(d.hold),
    ("ORG", None): lambda d, a: _effect(d.steering_origin),
    ("MVI", None): lambda d, a: _effect(lambda: d.move_distance(a[0], a[1], a[2])),
    ("MOV", None): lambda d, a: _effect(lambda: d.move(a[0], a[1])),
    ("STR", None): lambda d, a: _effect(lambda: d.steer_right(a[0])),
    ("STL", None): lambda d, a: _effect(lambda: d.steer_left(a[0])),
    ("STX", None): lambda d, a: _effect(lambda: d.steer_by(a[0])),
    ("ROT", None): lambda d, a: _effect(lambda: d.rotate(a[0])),
    ("TRC", None): lambda d, a: _effect(lambda: d.set_tracing(a[0])),
    ("TIM", None): lambda d, a: _effect(lambda: d.wait(a[0])),
    ("KYC", None): lambda d, a: _effect(d.clear_distance),
    ("KYO", None): lambda d, a: _odometry(d.read_distance()),
    ("SCN", None): lambda d, a: _effect(lambda: d.select_scene(a[0])),
    ("IMG", None): lambda d, a: _image(d.measure_image()),
    ("CAM", "Z"): lambda d, a: _effect(d.camera_origin),
    ("CAM", "U"): lambda d, a: _effect(d.camera_up),
    ("CAM", "D"): lambda d, a: _effect(d.camera_down),
    ("CAM", "A"): lambda d, a: _effect(lambda: d.camera_pan_angle(a[0])),
    ("CAM", "P"): lambda d, a: _effect(lambda: d.camera_pan_pulse(a[0])),
    ("CAM", "R"): lambda d, a: _value(d.camera_position()),
    ("ULT", "A"): lambda d, a: _value(d.ultrasonic("A")),
    ("ULT", "B"): lambda d, a: _value(d.ultrasonic("B")),
    ("ULT", "C"): lambda d, a: _value(d.ultrasonic("C")),
    ("ULT", "D"): lambda d, a: _value(d.ultrasonic("D")),
    ("LMP", None): lambda d, a: _effect(lambda: d.lamp(a[0])),
    ("INP", None): lambda d, a: _value(d.read_port(a[0])),
    ("OUT", None): lambda d, a: _effect(lambda: d.write_port(a[0], a[1])),
    ("FZO", None): lambda d, a: _effect(lambda: d.fuzzy_write(a[0], a[1])),
    ("FZI", None): lambda d, a: _fuzzy(d.fuzzy_read()),
}


def form_name(form: FormKey) -> str:
    """How a form is written in messages and traces: "MOV", "CAM A"."""
    mnemonic, selector = form
    return mnemonic if selector is None else f"{mnemonic} {selector}"


def checked(form: FormKey, outcome: Outcome) -> Outcome:
    """`outcome` if every value in it is one the form can give: a 16-bit signed integer,
    within the form's documented result range (language.Form.result_range: INP 0..255,
    CAM R 0..784); DeviceError otherwise, since a value outside it is the device's fault."""
    mnemonic, selector = form
    spec = BUILTINS[mnemonic].form(selector)
    assert spec is not None
    low, high = spec.result_range
    if outcome.result is not None and not (
            isinstance(outcome.result, int) and low <= outcome.result <= high):
        raise DeviceError(f"({form_name(form)}) returned {outcome.result!r}, outside "
                          f"its range {low}..{high}")
    for value in outcome.writes:
        if not (isinstance(value, int) and -32768 <= value <= 32767):
            raise DeviceError(f"({form_name(form)}) returned {value!r}, "
                              "which is not a 16-bit signed integer")
    return outcome


def perform(device: Device, form: FormKey, args: tuple[int, ...],
            line: int | None = None) -> Outcome:
    """Carry out one built-in call, made on source line `line`, on `device`, checking
    what comes back (`checked`)."""
    device.line = line
    return checked(form, BINDINGS[form](device, args))
