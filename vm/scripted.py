"""A deterministic Device driven by a sensor script, recording every command it gets.

The script says what each sensing call returns, in order, and when the guidance line is
lost; vm/sensor_script.py is its schema and loads it into a Script.

Each call takes the next reading of its list. A call whose reading the script does not
give (its list is used up, or there is none) ends the run at once with a device error
that names the reading and the device time: a script stands for a test of limited
length, and zeros or a repeated reading would let a loop run on for ever on readings
nobody wrote. `"after_last": "repeat"` asks for the other rule instead: a list's last
reading repeats, and a call with no list reads zeros. Values are 16-bit signed
integers (INP data 0..255, CAM R 0..784). spec/sensors.md is the user's page.

Line losses: `{"time": T}` at device time T ms; `{"during": "MOV"|"MVI", "nth": N,
"after": A}` A ms (default 1) after the N-th MOV or MVI call of the run (counting every
call, MOV 0,0 included) started, if that command is still in effect then. A loss at the
very moment an MVI covers its distance is too late for it; losses at the same
millisecond are one loss. `{"instruction": N}`: right
after the VM has run N instructions, between two instructions, as a vehicle's device
posts a loss from an interrupt; the device cannot see instructions, so whoever steps the
VM calls `lose_line` then (vm/drive.py), and an engine that counts no instructions (the
AST interpreter) cannot run such a script. A loss matters only while
motion is in effect (a non-zero MOV, or an MVI in progress) and tracing is on (mode 1-3);
see device.py for what each tracing mode does with it. Every loss is in the log
(`ScriptedDevice.log`), those that did nothing too, with why; `trace` holds only those
that mattered (the test vectors' contract).

Failures: a call named in "fail" (a form as the trace writes it: "TIM", "CAM R") fails
the N-th time it arrives: the device records it, then raises DeviceError, at once for a
built-in that takes no device time, at the end of its device time for one that does (as
a poll that answers an error). With "stop_fails" the device records STOP, then raises
DeviceError: the engine's stop after a fault fails.

The motion model (device time in integer milliseconds, starting at 0):
- TIM t waits t x 100 ms; MVI l,r,cm moves the centre at |l+r|/2 x 5 cm/s (a wheel speed
  unit is 5 cm/s), so it takes ceil(|cm| x 400 / |l+r|) ms; ROT a takes |a| x 10 ms;
  every other built-in that waits (language.Builtin.waits) takes 100 ms; the rest 0 ms.
- A loss interrupts only TIM and MVI (they return at the loss's time); any other call
  completes first, and the loss reaches the program after it.
- A device-time limit (`time_limit`, ms) ends a run whose clock would pass it with a
  device error, at the limit: a program waiting in a loop for a reading that never
  comes.

Each entry also carries the source line the engine was running when it was recorded:
`line`, which the engine's adapter sets before each call (Device.line), and the stepper
gives with a loss after an instruction count.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, TypeVar

from .device import (
    DeviceError,
    FuzzyReading,
    ImageReading,
    LineLost,
    MotionCommand,
    Odometry,
)
from .faults import RunResult
from .language import BUILTINS, lost_line_handler

# The script's schema and loader, imported from here too by the run stage, its report
# and the tools.
from .sensor_script import LossAfter as LossAfter
from .sensor_script import LossAt as LossAt
from .sensor_script import LossDuring as LossDuring
from .sensor_script import Script as Script
from .sensor_script import ScriptError as ScriptError
from .sensor_script import decode_script as decode_script
from .sensor_script import parse_script as parse_script

T = TypeVar("T")

WHEEL_UNIT_CM_PER_S = 5
STEP_MS = 100  # a waiting built-in with no duration of its own
ROT_MS_PER_DEGREE = 10


LOST = "LINE LOST"

# What a lost line did (TraceEntry.effect): the program jumps to its handler; tracing
# mode 1 drives on; a loss already waits for the program; nothing, as no motion is in
# effect or tracing is off (mode 0).
Effect = Literal["jump", "drive-on", "already-waiting", "no-motion", "tracing-off"]
IGNORED: frozenset[Effect] = frozenset({"no-motion", "tracing-off"})


@dataclass(frozen=True, slots=True)
class TraceEntry:
    """One command the device received (or a line it lost), at device time `time` ms.
    A LINE LOST entry's args are (mode,); `during` is the motion command in effect and
    `effect` what the loss did. `line` is the source line the engine was running."""

    time: int
    call: str
    args: tuple[int, ...] = ()
    result: tuple[int, ...] | None = None  # what a sensing call read
    line: int | None = field(default=None, compare=False)
    during: str | None = None
    effect: Effect | None = None

    def to_json(self) -> dict[str, Any]:
        """The entry as the test vectors write it (no source line: a stripped file has
        none)."""
        entry: dict[str, Any] = {"time": self.time, "call": self.call, "args": list(self.args)}
        if self.result is not None:
            entry["result"] = list(self.result)
        return entry

    @property
    def handler(self) -> int | None:
        """The label a lost line sent the program to (Table 4), if it did."""
        if self.effect != "jump" or self.during is None:
            return None
        return lost_line_handler(self.args[0], self.during)

    def describe(self) -> str:
        """The entry for people: `MOV 3,3`, `IMG -> 120 128 90 0`,
        `LINE LOST (mode 3, MOV) -> :96`."""
        if self.call == LOST:
            mode = f"mode {self.args[0]}" + (f", {self.during}" if self.during else "")
            if self.effect in (None, "jump"):
                return f"{LOST} ({mode}) -> :{self.handler}"
            return f"{LOST} ({mode}): {_EFFECT_TEXT[self.effect]}"
        text = self.call + (" " + ",".join(map(str, self.args)) if self.args else "")
        if self.result is not None:
            text += " -> " + " ".join(map(str, self.result))
        return text


_EFFECT_TEXT: dict[str | None, str] = {
    "drive-on": "mode 1 drives straight on, no jump",
    "already-waiting": "a loss already waits for the program",
    "no-motion": "ignored, no motion in effect",
    "tracing-off": "ignored, tracing is off",
}


def run_document(result: RunResult, trace: Sequence[TraceEntry]) -> dict[str, Any]:
    """A run on this device as JSON data: the fields of `rl1c run --format json` that an
    `exec:` engine of `rl1c fuzz` prints too (spec/optimization.md, section 5)."""
    return {"status": result.status(), "variables": result.named(),
            "trace": [entry.to_json() for entry in trace]}


# The device ----------------------------------------------------------------------------


@dataclass(slots=True)
class _Motion:
    """The motion in effect: a non-zero MOV (no end) or an MVI (ends at `end`)."""

    command: MotionCommand
    nth: int
    start: int
    end: int | None = None
    args: tuple[int, ...] = ()

    def describe(self) -> str:
        return f"({self.command} {','.join(map(str, self.args))})"


class ScriptedDevice:
    """A Device whose sensors replay a Script and whose clock follows the motion model
    above. `trace` lists every command received, in order."""

    def __init__(self, script: Script | None = None, time_limit: int | None = None) -> None:
        self.script = script or Script()
        self.time_limit = time_limit  # ms of device time; None: no limit
        self.trace: list[TraceEntry] = []
        self.log: list[TraceEntry] = []  # the trace, and the losses that did nothing
        self.line: int | None = None  # the engine's source line (Device.line)
        self.time = 0
        self.mode = 0
        self._motion: _Motion | None = None
        self._calls = {"MOV": 0, "MVI": 0}
        self.pending: LineLost | None = None
        # Each loss is looked up by bisection, so that a run costs time linear in its
        # script, however many losses it holds.
        self._losses_at = sorted(loss.time for loss in self.script.losses
                                 if isinstance(loss, LossAt))
        self._losses_during: dict[tuple[str, int], list[int]] = {}
        for loss in self.script.losses:
            if isinstance(loss, LossDuring):
                self._losses_during.setdefault((loss.command, loss.nth), []).append(loss.after)
        for afters in self._losses_during.values():
            afters.sort()
        self._read_counts: dict[str, int] = {}
        self._arrivals: dict[str, int] = {}  # calls of each form so far, for "fail"
        self._failing: str | None = None  # why the waiting built-in under way fails
        self._met: set[LossAt | LossDuring | LossAfter] = set()  # the losses that happened

    # Bookkeeping

    @property
    def motion(self) -> str | None:
        """The motion command in effect, as `(MOV 3,3)`; None when the vehicle stands."""
        return self._motion.describe() if self._motion is not None else None

    def _record(self, call: str, *args: int, result: tuple[int, ...] | None = None) -> None:
        entry = TraceEntry(self.time, call, args, result, self.line)
        self.trace.append(entry)
        self.log.append(entry)
        arrived = self._arrivals.get(call, 0) + 1
        self._arrivals[call] = arrived
        if self.script.failures.get(call) == arrived:
            failure = f"({call}) failed: the sensor script says its call {arrived} fails"
            if not BUILTINS[call.split()[0]].waits:
                raise DeviceError(failure)
            self._failing = failure  # at the end of its device time

    def _next(self, key: str, readings: tuple[T, ...], nothing: T, call: str,
              *args: int) -> T:
        """The next reading of `key` for a `call` with `args`; when the script has none
        left, the other rule it chose, or the call recorded and a DeviceError."""
        count = self._read_counts.get(key, 0)
        self._read_counts[key] = count + 1
        if count < len(readings):
            return readings[count]
        if self.script.after_last == "repeat":
            return readings[-1] if readings else nothing
        self._record(call, *args)
        form = f"({key})"
        if not self.script.name:
            raise DeviceError(f"{form} at {self.time} ms has no reading: no sensor script "
                              "was given")
        if not readings:
            raise DeviceError(f"{form} at {self.time} ms has no reading: the sensor script "
                              f"{self.script.name} gives no {key} readings")
        raise DeviceError(f"{form} at {self.time} ms has no reading: it is call "
                          f"{count + 1}, and the sensor script {self.script.name} gives "
                          f"{len(readings)} {key} reading{'s' if len(readings) > 1 else ''}")

    def _next_loss(self, until: int) -> int | None:
        """The time of the next loss that could matter in (time, until]."""
        times = []
        at = bisect.bisect_right(self._losses_at, self.time)
        if at < len(self._losses_at) and self._losses_at[at] <= until:
            times.append(self._losses_at[at])
        motion = self._motion
        if motion is not None:
            afters = self._losses_during.get((motion.command, motion.nth), [])
            during = bisect.bisect_right(afters, self.time - motion.start)
            if during < len(afters) and motion.start + afters[during] <= until:
                times.append(motion.start + afters[during])
        return min(times, default=None)

    def _advance(self, duration: int, interruptible: bool) -> None:
        """Let the device time of a waiting built-in pass; then it fails, if the script
        says so (a failing poll). Passing the time limit ends the run at the limit."""
        limit = self.time_limit
        if limit is not None and self.time + duration > limit:
            self._pass_time(limit - self.time, interruptible)
            if self.time >= limit:
                self._failing = None
                raise DeviceError(f"the run reached its device-time limit of "
                                  f"{limit / 1000:g} s, during ({self.trace[-1].describe()})")
        else:
            self._pass_time(duration, interruptible)
        failing, self._failing = self._failing, None
        if failing is not None:
            raise DeviceError(failing)

    def _pass_time(self, duration: int, interruptible: bool) -> None:
        """Let `duration` ms of device time pass, meeting motion ends and line losses in
        time order; an interruptible wait ends at the first loss the program must hear."""
        until = self.time + duration
        while True:
            motion = self._motion
            loss = self._next_loss(until)
            motion_end = motion.end if motion is not None else None
            if motion_end is not None and motion_end <= until and (
                    loss is None or motion_end <= loss):
                self.time = motion_end
                self._motion = None
                continue
            if loss is None:
                self.time = until
                return
            self.time = loss
            self._met.add(LossAt(loss))
            if motion is not None:
                self._met.add(LossDuring(motion.command, motion.nth, loss - motion.start))
            if self.lose_line() and interruptible:
                return

    def lose_line_after(self, instruction: int, line: int | None) -> bool:
        """The line is lost after the VM's `instruction`-th instruction (LossAfter), which
        was on source line `line`."""
        self.line = line
        self._met.add(LossAfter(instruction))
        return self.lose_line()

    def losses_not_met(self) -> list[tuple[int, LossAt | LossDuring | LossAfter, str]]:
        """The script's losses that have not happened (yet): each with its index in
        `line_lost` and why, so that a report drops none silently."""
        missed = []
        for index, loss in enumerate(self.script.losses):
            if loss in self._met:
                continue
            if isinstance(loss, LossDuring) and self._calls[loss.command] >= loss.nth:
                why = (f"that {loss.command} was not in effect {loss.after} ms after "
                       "it started")
            elif isinstance(loss, LossDuring):
                calls = self._calls[loss.command]
                why = f"the run made {calls} {loss.command} call{'s' if calls != 1 else ''}"
            else:
                why = "the run ended before it"
            missed.append((index, loss, why))
        return missed

    def lose_line(self) -> bool:
        """The line is lost now; True if the program is to hear of it."""
        motion = self._motion
        if motion is None or self.mode == 0:
            self.log.append(TraceEntry(self.time, LOST, (self.mode,), None, self.line,
                                       motion.command if motion is not None else None,
                                       "no-motion" if motion is None else "tracing-off"))
            return False
        effect: Effect = ("drive-on" if self.mode == 1 else
                          "already-waiting" if self.pending is not None else "jump")
        entry = TraceEntry(self.time, LOST, (self.mode,), None, self.line,
                           motion.command, effect)
        self.trace.append(entry)
        self.log.append(entry)
        if effect != "jump":
            return False
        self.pending = LineLost(motion.command, self.mode)
        if self.mode == 2:
            self._motion = None
        return True

    def _stopped(self, call: str) -> None:
        self._record(call)
        self._motion = None

    def _takes(self, call: str, *args: int, result: tuple[int, ...] | None = None) -> None:
        """Record a command of fixed duration and let its time pass."""
        self._record(call, *args, result=result)
        if BUILTINS[call.split()[0]].waits:
            self._advance(STEP_MS, interruptible=False)

    # Motion and steering

    def free(self) -> None:
        self._stopped("FRE")

    def hold(self) -> None:
        self._stopped("HLD")

    def steering_origin(self) -> None:
        self._takes("ORG")

    def move_distance(self, left: int, right: int, cm: int) -> None:
        self._calls["MVI"] += 1
        self._record("MVI", left, right, cm)
        if cm == 0:
            self._motion = None
            self._advance(0, interruptible=True)  # no time passes, but it may fail
            return
        if left + right == 0:
            raise DeviceError(f"(MVI {left},{right},{cm}) would never end: with wheel speeds "
                              f"{left} and {right} the vehicle's centre does not move")
        duration = math.ceil(abs(cm) * 1000 * 2 / (abs(left + right) * WHEEL_UNIT_CM_PER_S))
        self._motion = _Motion("MVI", self._calls["MVI"], self.time, self.time + duration,
                               (left, right, cm))
        self._advance(duration, interruptible=True)

    def move(self, left: int, right: int) -> None:
        self._calls["MOV"] += 1
        self._record("MOV", left, right)
        moving = left != 0 or right != 0
        self._motion = (_Motion("MOV", self._calls["MOV"], self.time, None, (left, right))
                        if moving else None)

    def steer_right(self, degrees: int) -> None:
        self._takes("STR", degrees)

    def steer_left(self, degrees: int) -> None:
        self._takes("STL", degrees)

    def steer_by(self, tenths: int) -> None:
        self._takes("STX", tenths)

    def rotate(self, degrees: int) -> None:
        self._record("ROT", degrees)
        self._advance(abs(degrees) * ROT_MS_PER_DEGREE, interruptible=False)

    def set_tracing(self, mode: int) -> None:
        self._record("TRC", mode)
        self.mode = mode

    def wait(self, tenths: int) -> None:
        self._record("TIM", tenths)
        self._advance(tenths * 100, interruptible=True)

    # Sensing, camera, I/O, fuzzy board

    def clear_distance(self) -> None:
        self._takes("KYC")

    def read_distance(self) -> Odometry:
        reading = self._next("KYO", self.script.odometry, Odometry(0, 0, 0), "KYO")
        self._takes("KYO", result=(reading.centre, reading.right, reading.left))
        return reading

    def select_scene(self, scene: int) -> None:
        self._takes("SCN", scene)

    def measure_image(self) -> ImageReading:
        reading = self._next("IMG", self.script.images, ImageReading(0, 0, 0, 0), "IMG")
        self._takes("IMG", result=(reading.area, reading.x, reading.y, reading.z))
        return reading

    def camera_origin(self) -> None:
        self._takes("CAM Z")

    def camera_up(self) -> None:
        self._takes("CAM U")

    def camera_down(self) -> None:
        self._takes("CAM D")

    def camera_pan_angle(self, degrees: int) -> None:
        self._takes("CAM A", degrees)

    def camera_pan_pulse(self, pulse: int) -> None:
        self._takes("CAM P", pulse)

    def camera_position(self) -> int:
        position = self._next("CAM R", self.script.camera, 0, "CAM R")
        self._takes("CAM R", result=(position,))
        return position

    def ultrasonic(self, sensor: str) -> int:
        distance = self._next(f"ULT {sensor}", self.script.ultrasonic.get(sensor, ()), 0,
                              f"ULT {sensor}")
        self._takes(f"ULT {sensor}", result=(distance,))
        return distance

    def lamp(self, on: int) -> None:
        self._takes("LMP", on)

    def read_port(self, port: int) -> int:
        data = self._next(f"INP {port}", self.script.ports.get(port, ()), 0, "INP", port)
        self._takes("INP", port, result=(data,))
        return data

    def write_port(self, port: int, data: int) -> None:
        self._takes("OUT", port, data)

    def fuzzy_write(self, a: int, b: int) -> None:
        self._takes("FZO", a, b)

    def fuzzy_read(self) -> FuzzyReading:
        reading = self._next("FZI", self.script.fuzzy, FuzzyReading(0, 0), "FZI")
        self._takes("FZI", result=(reading.s, reading.t))
        return reading

    # Engine services

    def stop(self) -> None:
        self._stopped("STOP")
        if self.script.stop_fails:
            raise DeviceError("the sensor script says stopping fails")

    def poll_event(self) -> LineLost | None:
        event, self.pending = self.pending, None
        return event
