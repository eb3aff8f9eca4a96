"""The sensor script: its schema, and loading and validating it into a Script that
vm/scripted.py's device replays (spec/sensors.md is the user's page; JSON Schema for
editors: spec/schemas/sensors.schema.json).

The script (JSON, or TOML when the file name ends in .toml) says what each sensing call
returns, in order, and when the guidance line is lost:

    {
      "IMG": [{"area": 120, "x": 130, "y": 100, "z": 0}, ...],
      "KYO": [{"centre": 50, "right": 52, "left": 48}, ...],
      "CAM R": [392, ...],
      "ULT A": [150, ...],          (also "ULT B", "ULT C", "ULT D")
      "INP": {"3": [1, 0], ...},    (per input port, the port number in decimal)
      "FZI": [{"s": 1, "t": -2}, ...],
      "line_lost": [{"time": 2500}, {"during": "MVI", "nth": 1, "after": 300},
                    {"instruction": 40}],
      "fail": {"ULT A": 2, ...},     (the 2nd ULT A call of the run fails)
      "stop_fails": true,
      "after_last": "stop",          (or "repeat")
      "comment": "free text, ignored"
    }

Values are 16-bit signed integers (INP data 0..255, CAM R 0..784). The file's schema is
`ScriptFile` (msgspec, through rl1.vm.config, the configuration files' one validation
layer); the checks that span keys (a port's number, a call's form, a loss's shape) are
here. Every failure is a ScriptError `file:line: key: what is wrong`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal, get_args

import msgspec
from msgspec import UNSET, Meta, Struct, UnsetType

from .config import (
    INPUT_PORTS,
    SENSOR_SCRIPT,
    WORLD,
    Byte,
    ConfigError,
    Int16,
    PortName,
    Syntax,
    convert,
    error_at,
    found,
    one_of,
    read_document,
    written_key,
)
from .config_lines import KeyPath
from .device import FuzzyReading, ImageReading, MotionCommand, Odometry, form_name
from .language import BUILTINS

AfterLast = Literal["stop", "repeat"]
AFTER_LAST: tuple[AfterLast, ...] = get_args(AfterLast)


class ScriptError(Exception):
    """A sensor script that cannot be used; the message starts `file:line: key:`."""


@dataclass(frozen=True, slots=True)
class LossAt:
    """The line is lost at device time `time` ms."""

    time: int

    def to_json(self) -> dict[str, Any]:
        """The loss as the script writes it."""
        return {"time": self.time}


@dataclass(frozen=True, slots=True)
class LossDuring:
    """The line is lost `after` ms into the `nth` call of `command`."""

    command: MotionCommand
    nth: int
    after: int

    def to_json(self) -> dict[str, Any]:
        return {"during": self.command, "nth": self.nth, "after": self.after}


@dataclass(frozen=True, slots=True)
class LossAfter:
    """The line is lost right after the VM's `instruction`-th instruction."""

    instruction: int

    def to_json(self) -> dict[str, Any]:
        return {"instruction": self.instruction}


@dataclass(frozen=True, slots=True)
class Script:
    """A validated sensor script, as the device replays it."""

    images: tuple[ImageReading, ...] = ()
    odometry: tuple[Odometry, ...] = ()
    camera: tuple[int, ...] = ()
    ultrasonic: dict[str, tuple[int, ...]] = field(default_factory=dict)
    ports: dict[int, tuple[int, ...]] = field(default_factory=dict)
    fuzzy: tuple[FuzzyReading, ...] = ()
    losses: tuple[LossAt | LossDuring | LossAfter, ...] = ()
    failures: dict[str, int] = field(default_factory=dict)  # a form -> the call that fails
    stop_fails: bool = False
    after_last: AfterLast = "stop"
    name: str = field(default="", compare=False)  # its file; "" when no script was given

    @property
    def instruction_losses(self) -> tuple[int, ...]:
        """The instruction counts after which the line is lost, in order."""
        return tuple(sorted(loss.instruction for loss in self.losses
                            if isinstance(loss, LossAfter)))


# The file's schema -------------------------------------------------------------------

FORMS = frozenset(form_name((mnemonic, form.selector)) for mnemonic, builtin in BUILTINS.items()
                  if mnemonic != "END" for form in builtin.forms)

_NON_EMPTY = Meta(min_length=1, extra={
    "expected": "a list of at least one reading (leave the key out for none)"})
Count = Annotated[int, Meta(ge=1, le=2**31 - 1)]
CameraPosition = Annotated[int, Meta(ge=0, le=784)]


class ImageFields(Struct, forbid_unknown_fields=True):
    """What (IMG) reads: the area (its result, also written to w) and the centroid."""

    area: Int16
    x: Int16
    y: Int16
    z: Int16


class OdometryFields(Struct, forbid_unknown_fields=True):
    """What (KYO) reads: the distance moved (its result), u (right wheel), v (left)."""

    centre: Int16
    right: Int16
    left: Int16


class FuzzyFields(Struct, forbid_unknown_fields=True):
    """What (FZI) reads: the fuzzy board's outputs."""

    s: Int16
    t: Int16


class LossFields(Struct, forbid_unknown_fields=True):
    """A loss of the guidance line: {"time": MS}, {"instruction": N}, or
    {"during": "MOV"|"MVI", "nth": N, "after": MS}."""

    time: Count | UnsetType = UNSET
    instruction: Annotated[int, Meta(ge=0, le=2**31 - 1)] | UnsetType = UNSET
    during: Literal["MOV", "MVI"] | UnsetType = UNSET
    nth: Count | UnsetType = UNSET
    after: Count | UnsetType = UNSET


class ScriptFile(Struct, forbid_unknown_fields=True, kw_only=True):
    """A sensor script of `rl1c run --sensors` (spec/sensors.md)."""

    images: Annotated[list[ImageFields], _NON_EMPTY] = msgspec.field(
        name="IMG", default_factory=list)
    odometry: Annotated[list[OdometryFields], _NON_EMPTY] = msgspec.field(
        name="KYO", default_factory=list)
    camera: Annotated[list[CameraPosition], _NON_EMPTY] = msgspec.field(
        name="CAM R", default_factory=list)
    ultrasonic_a: Annotated[list[Int16], _NON_EMPTY] = msgspec.field(
        name="ULT A", default_factory=list)
    ultrasonic_b: Annotated[list[Int16], _NON_EMPTY] = msgspec.field(
        name="ULT B", default_factory=list)
    ultrasonic_c: Annotated[list[Int16], _NON_EMPTY] = msgspec.field(
        name="ULT C", default_factory=list)
    ultrasonic_d: Annotated[list[Int16], _NON_EMPTY] = msgspec.field(
        name="ULT D", default_factory=list)
    ports: Annotated[dict[PortName, Annotated[list[Byte], _NON_EMPTY]], Meta(extra={
        "expected": 'an object from port number to a list of readings, e.g. {"3": [1, 0]}'})
    ] = msgspec.field(name="INP", default_factory=dict)
    fuzzy: Annotated[list[FuzzyFields], _NON_EMPTY] = msgspec.field(
        name="FZI", default_factory=list)
    line_lost: Annotated[list[LossFields], _NON_EMPTY] = []
    fail: Annotated[dict[str, Count], Meta(extra={
        "expected": 'an object from a call to the one that fails, e.g. {"TIM": 2}'})] = {}
    stop_fails: bool = False
    after_last: AfterLast = "stop"
    comment: str = ""


# Loading ------------------------------------------------------------------------------


def decode_script(data: bytes, name: str) -> Script:
    """Decode and validate the bytes of a sensor script, TOML when `name` ends in .toml
    and JSON otherwise; ScriptError says what is wrong and where."""
    syntax: Syntax = "toml" if Path(name).suffix.lower() == ".toml" else "json"
    try:
        document, text = read_document(data, name, syntax)
    except ConfigError as error:
        raise ScriptError(str(error)) from error  # which rl1c places
    return _load(document, name, text, syntax)


def parse_script(document: object, name: str = "<script>") -> Script:
    """A Script from decoded JSON/TOML data; ScriptError names the offending key."""
    return _load(document, name, "", "json")


def _load(document: object, name: str, text: str, syntax: Syntax) -> Script:
    try:
        if not isinstance(document, dict):
            raise ConfigError(name, None, "", "the script must be an object of sensor "
                              f"lists, found {found(document, syntax)}")
        SENSOR_SCRIPT.refuse_other(document, name, WORLD)
        file = convert(document, ScriptFile, name, text, syntax)
        return _Script(file, name, text, syntax).build()
    except ConfigError as error:
        raise ScriptError(str(error)) from error  # which rl1c places


class _Script:
    """The checks that span keys, and the Script they give."""

    def __init__(self, file: ScriptFile, name: str, text: str, syntax: Syntax) -> None:
        self.file = file
        self.name = name
        self.text = text
        self.syntax = syntax

    def fail(self, path: KeyPath, detail: str) -> ConfigError:
        return error_at(self.name, self.text, path, detail, self.syntax)

    def build(self) -> Script:
        file = self.file
        ultrasonic = {letter: tuple(readings) for letter, readings in (
            ("A", file.ultrasonic_a), ("B", file.ultrasonic_b), ("C", file.ultrasonic_c),
            ("D", file.ultrasonic_d)) if readings}  # a list given is never empty
        return Script(
            images=tuple(ImageReading(i.area, i.x, i.y, i.z) for i in file.images),
            odometry=tuple(Odometry(o.centre, o.right, o.left) for o in file.odometry),
            camera=tuple(file.camera), ultrasonic=ultrasonic, ports=self.ports(),
            fuzzy=tuple(FuzzyReading(f.s, f.t) for f in file.fuzzy),
            losses=tuple(self.loss(loss, i) for i, loss in enumerate(file.line_lost)),
            failures=self.failures(), stop_fails=file.stop_fails,
            after_last=file.after_last, name=self.name)

    def ports(self) -> dict[int, tuple[int, ...]]:
        ports = {}
        for key, readings in self.file.ports.items():
            port = int(key)
            if not INPUT_PORTS.low <= port <= INPUT_PORTS.high:
                raise self.fail(("INP", key), f"{port} is outside {INPUT_PORTS.low}.."
                                              f"{INPUT_PORTS.high}, the input ports")
            ports[port] = tuple(readings)
        return ports

    def failures(self) -> dict[str, int]:
        for call in self.file.fail:
            if call not in FORMS:
                raise self.fail(("fail", call), "not a built-in form; " + one_of(
                    call, sorted(FORMS), lambda form: written_key(form, self.syntax)))
        return dict(self.file.fail)

    def loss(self, loss: LossFields, index: int) -> LossAt | LossDuring | LossAfter:
        given = {key for key in ("time", "instruction", "during", "nth", "after")
                 if getattr(loss, key) is not UNSET}
        if given == {"time"} and not isinstance(loss.time, UnsetType):
            return LossAt(loss.time)
        if given == {"instruction"} and not isinstance(loss.instruction, UnsetType):
            return LossAfter(loss.instruction)
        if given in ({"during", "nth"}, {"during", "nth", "after"}) and not isinstance(
                loss.during, UnsetType) and not isinstance(loss.nth, UnsetType):
            after = 1 if isinstance(loss.after, UnsetType) else loss.after
            return LossDuring(loss.during, loss.nth, after)
        keys = ", ".join(f'"{key}"' for key in sorted(given)) or "no keys"
        raise self.fail(("line_lost", index), 'expected {"time": MS}, {"instruction": N} '
                        'or {"during": "MOV"|"MVI", "nth": N, "after": MS}, found ' + keys)
