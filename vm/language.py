"""The facts of RL/I that every stage shares, each written once: the variables and their
index, the built-in functions (the paper's Tables 2 and 3), and where a lost guidance
line jumps (Table 4).

This module is the bottom layer of the project: it imports nothing of rl1. Its rows
are frozen singletons, compared by identity (`eq=False`), which also spares generating
equality and hashing for them at every start. The built-in table serves every stage:
the checker (arity, kinds, ranges), the code generator (opcodes and device features),
the VMs (which reserved variables a call writes) and the language server (hover,
completion, signature help, inlay hints). spec/language.md renders the same facts for
people; keep the two in step.
"""

from __future__ import annotations

from enum import Enum
from typing import NamedTuple


class Feature(Enum):
    """Device features a program may need; the .ilc header lists those it uses."""

    MOTION = 0
    STEERING = 1
    CAMERA = 2
    VISION = 3
    ULTRASONIC = 4
    IO = 5
    FUZZY = 6


class Param(NamedTuple):
    """One parameter of a built-in: its name, range and meaning."""

    name: str
    low: int
    high: int
    meaning: str

    def describe(self) -> str:
        return f"{self.name}: {self.meaning}, {self.low}..{self.high}"


class Form(NamedTuple):
    """One way to call a built-in. Most have a single form with `selector` None;
    `(CAM ...)` and `(ULT ...)` have one form per selector letter."""

    selector: str | None
    params: tuple[Param, ...]
    summary: str
    result: str | None = None  # what the call returns, None if it returns nothing
    writes: tuple[str, ...] = ()  # reserved variables the call sets
    result_range: tuple[int, int] = (-32768, 32767)  # what the device may return

    @property
    def returns_value(self) -> bool:
        return self.result is not None


class Builtin(NamedTuple):
    """A built-in function (a row of Table 2 or 3) and the forms it is called in."""

    mnemonic: str
    name: str  # the paper's expansion of the mnemonic
    group: str  # "motion" (Table 2), "sensing" (Table 3) or "control" (Table 1)
    feature: Feature | None
    waits: bool  # True when the call takes device time before the next statement runs
    forms: tuple[Form, ...]

    @property
    def has_selector(self) -> bool:
        return self.forms[0].selector is not None

    def form(self, selector: str | None) -> Form | None:
        return next((form for form in self.forms if form.selector == selector), None)


WHEEL_SPEED = "wheel speed"


def _one(summary: str, *params: Param, result: str | None = None,
         writes: tuple[str, ...] = (), result_range: tuple[int, int] = (-32768, 32767)
         ) -> tuple[Form, ...]:
    return (Form(None, params, summary, result, writes, result_range),)


BUILTINS: dict[str, Builtin] = {
    b.mnemonic: b
    for b in (
        Builtin("END", "End", "control", None, False,
                _one("End the program. Motion in effect is not stopped by this.")),
        Builtin("FRE", "Free", "motion", Feature.MOTION, False,
                _one("Free the drive axes (the wheels turn freely).")),
        Builtin("HLD", "Hold", "motion", Feature.MOTION, False,
                _one("Hold (lock) the drive axes.")),
        Builtin("ORG", "Origin", "motion", Feature.STEERING, True,
                _one("Return the steering to its origin.")),
        Builtin("MVI", "Move mediate", "motion", Feature.MOTION, True,
                _one("Move at the given wheel speeds for a distance; waits until done.",
                     Param("l", -12, 12, "left " + WHEEL_SPEED),
                     Param("r", -12, 12, "right " + WHEEL_SPEED),
                     Param("cm", -1900, 1900, "distance in cm"))),
        Builtin("MOV", "Move", "motion", Feature.MOTION, False,
                _one("Start moving at the given wheel speeds; the next statement runs at once.",
                     Param("l", -12, 12, "left " + WHEEL_SPEED),
                     Param("r", -12, 12, "right " + WHEEL_SPEED))),
        Builtin("STR", "Steer Right", "motion", Feature.STEERING, True,
                _one("Turn the steering right.", Param("deg", 0, 180, "angle in degrees"))),
        Builtin("STL", "Steer Left", "motion", Feature.STEERING, True,
                _one("Turn the steering left.", Param("deg", 0, 180, "angle in degrees"))),
        Builtin("STX", "Steer X", "motion", Feature.STEERING, True,
                _one("Turn the steering by a signed angle in 0.1 degree units (+ left, - right).",
                     Param("tenths", -1800, 1800, "angle in 0.1 degrees"))),
        Builtin("ROT", "Rotate", "motion", Feature.MOTION, True,
                _one("Turn on the spot by differential wheel drive (PWS).",
                     Param("deg", -360, 360, "angle in degrees, + left, - right"))),
        Builtin("TRC", "Trace", "motion", Feature.MOTION, False,
                _one("Set the line-tracing mode (what a lost line does, Table 4).",
                     Param("mode", 0, 3, "tracing mode"))),
        Builtin("TIM", "Time", "motion", None, True,
                _one("Stop the program and wait, in 0.1 s units.",
                     Param("tenths", 1, 100, "time in 0.1 s"))),
        Builtin("KYC", "Kyori Clear", "sensing", Feature.MOTION, False,
                _one("Clear the distance counters.")),
        Builtin("KYO", "Kyori", "sensing", Feature.MOTION, False,
                _one("Read the distance counters.",
                     result="movement of the vehicle centre (cm)", writes=("u", "v"))),
        Builtin("SCN", "Scene", "sensing", Feature.VISION, False,
                _one("Switch the vision sensor's scene (a stored recognition set-up).",
                     Param("scene", 0, 7, "scene number"))),
        Builtin("IMG", "Image", "sensing", Feature.VISION, True,
                _one("Measure with the vision sensor.",
                     result="area of the recognised image (pixels)",
                     writes=("w", "x", "y", "z"))),
        Builtin("CAM", "Camera", "sensing", Feature.CAMERA, True, (
            Form("Z", (), "Camera to its origin."),
            Form("U", (), "Tilt the camera up."),
            Form("D", (), "Tilt the camera down."),
            Form("A", (Param("deg", 0, 180, "pan angle in degrees"),),
                 "Pan the camera to an angle."),
            Form("P", (Param("pulse", 0, 784, "pan pulse position"),),
                 "Pan the camera to a pulse position."),
            Form("R", (), "Read the camera's pan position.",
                 result="pan pulse position (0..784)", result_range=(0, 784)),
        )),
        Builtin("ULT", "Ultra", "sensing", Feature.ULTRASONIC, True, tuple(
            Form(letter, (), f"Ultrasonic range reading from sensor {letter}.",
                 result="distance (cm)")
            for letter in "ABCD"
        )),
        Builtin("LMP", "Lamp", "sensing", Feature.VISION, False,
                _one("Switch the lighting off or on.", Param("on", 0, 1, "0 off, 1 on"))),
        Builtin("INP", "Input", "sensing", Feature.IO, False,
                _one("Read an input port.", Param("port", 0, 0x7D, "input port"),
                     result="the port's data (0..255)", result_range=(0, 255))),
        Builtin("OUT", "Output", "sensing", Feature.IO, False,
                _one("Write data to an output port.", Param("port", 0, 0x7D, "output port"),
                     Param("data", 0, 255, "data byte"))),
        Builtin("FZO", "Fuzzy Out", "sensing", Feature.FUZZY, False,
                _one("Write two values to the fuzzy-logic board.",
                     Param("a", -32768, 32767, "first value"),
                     Param("b", -32768, 32767, "second value"))),
        Builtin("FZI", "Fuzzy In", "sensing", Feature.FUZZY, False,
                _one("Read the fuzzy-logic board into s and t.", writes=("s", "t"))),
    )
}

RESERVED_VARIABLES = "stuvwxyz"
VARIABLES = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz@"
"""The 53 variables in their index order (the .ilc variable index)."""
VARIABLE_INDEX: dict[str, int] = {name: index for index, name in enumerate(VARIABLES)}


class LostLineRule(NamedTuple):
    """One row of Table 4: a line lost in tracing `mode` while `command` (MOV or MVI)
    is in effect jumps to `label`; `stops` tells whether the command stops first (mode 2)
    or goes on (mode 3, an MVI then running on in the background)."""

    mode: int
    command: str
    label: int
    stops: bool


LOST_LINE_RULES = (
    LostLineRule(2, "MOV", 98, stops=True),
    LostLineRule(2, "MVI", 99, stops=True),
    LostLineRule(3, "MOV", 96, stops=False),
    LostLineRule(3, "MVI", 97, stops=False),
)
"""Table 4. Mode 0 does not trace, mode 1 drives straight until it finds the line again:
neither jumps."""

_HANDLER_BY_EVENT = {(rule.mode, rule.command): rule.label for rule in LOST_LINE_RULES}

HANDLER_LABELS = range(min(_HANDLER_BY_EVENT.values()), max(_HANDLER_BY_EVENT.values()) + 1)
"""`:96`-`:99`: where a lost guidance line sends the program (Table 4)."""


def lost_line_handler(mode: int, command: str) -> int | None:
    """The label a line lost in tracing `mode` during `command` jumps to; None for no
    jump."""
    return _HANDLER_BY_EVENT.get((mode, command))


_SIGNIFICANT_DIGITS = 18
TOO_LONG: int = 10**_SIGNIFICANT_DIGITS
"""What a decimal number of more significant digits stands for: out of every range that
RL/I, the .ils text or a sensor script accepts."""


def decimal_value(text: str) -> int:
    """The value of a decimal integer written as `text` (an optional sign, then digits).
    A number too long to fit anything is taken as TOO_LONG with its sign, so that it gets
    the same out-of-range message as `99999` instead of costing time (or Python's limit
    on converting long digit strings) to convert."""
    digits = text.lstrip("+-").lstrip("0")
    if len(digits) > _SIGNIFICANT_DIGITS:
        return -TOO_LONG if text.startswith("-") else TOO_LONG
    return int(text)


def writers_of(variable: str) -> list[tuple[Builtin, Form]]:
    """The built-in forms that set a reserved variable."""
    return [(b, form) for b in BUILTINS.values() for form in b.forms if variable in form.writes]
