"""The hardware interface: how a VM that must never block drives the vehicle.

This is the Python form of spec/rl1_hardware.h, which the C VM of the firmware
implements (spec/ilc.md, section 12). A built-in that takes device time
(`language.Builtin.waits`: MVI, TIM, ROT, ORG, STR, STL, STX, IMG, CAM, ULT) is
*started*, then *polled* until it answers done or error; any other built-in is one
*call*. Every callback answers with a `Status`. Lost lines reach the VM through a
one-slot mailbox: `pending` looks at it, `take_event` empties it.

`Blocking` adapts a blocking `Device` (device.py): it carries out the whole built-in
when it is started, so its first poll answers done, or the error the device raised
meanwhile; it tells the device the source line of each call (Device.line).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import Enum
from typing import Protocol

from .device import BINDINGS, NOTHING, Device, DeviceError, FormKey, LineLost, Outcome


class Status(Enum):
    """What a callback answers (RL1_OK, RL1_BUSY, RL1_ERROR in C)."""

    OK = 0  # done; a poll's or a call's Outcome holds what a sensing call read
    BUSY = 1  # only from a poll: the built-in is still taking device time
    ERROR = 2  # the device failed or refused; `message` says why


@dataclass(frozen=True, slots=True)
class Answer:
    status: Status
    outcome: Outcome = NOTHING
    message: str = ""


OK = Answer(Status.OK)
BUSY = Answer(Status.BUSY)
BUSY_OUT_OF_TURN = "the device answered busy where only a poll may (spec/ilc.md 12.5)"


def refusal(answer: Answer) -> str:
    """Why an answer other than OK fails the run: its message, or for BUSY from any
    callback but poll, that it came out of turn (a device error, as in C)."""
    return BUSY_OUT_OF_TURN if answer.status is Status.BUSY else answer.message


class Hardware(Protocol):
    """The vehicle as the VM drives it. Arguments arrive range-checked; the VM checks
    what comes back (device.checked) before writing it anywhere."""

    def begin(self) -> Answer:
        """A program is about to run its first instruction."""

    def call(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        """Carry out a built-in that takes no device time."""

    def start(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        """Start a built-in that takes device time; OK or ERROR."""

    def poll(self) -> Answer:
        """The started built-in: BUSY, OK (with what it read) or ERROR."""

    def stop(self) -> Answer:
        """Stop the vehicle at once (a fault)."""

    def end(self) -> Answer:
        """The program is over, by (END) or by a fault (after `stop`)."""

    @property
    def pending(self) -> LineLost | None:
        """The lost-line event in the mailbox, if any; looking takes nothing."""

    def take_event(self) -> LineLost | None:
        """The lost-line event in the mailbox, if any, emptying it."""


def _no_line() -> int | None:
    return None


class Blocking:
    """A blocking Device as Hardware: a started built-in runs to its end at once.
    `line` says the source line of the VM's call under way (Machine.current_line)."""

    def __init__(self, device: Device, line: Callable[[], int | None] = _no_line) -> None:
        self.device = device
        self.line = line
        self._started = OK

    def _perform(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        self.device.line = self.line()
        try:
            return Answer(Status.OK, BINDINGS[form](self.device, args))
        except DeviceError as error:
            return Answer(Status.ERROR, message=str(error))

    def begin(self) -> Answer:
        return OK  # a Device is ready when made

    def call(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        return self._perform(form, args)

    def start(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        # Whatever happened while the device did its work is what the poll answers.
        self._started = self._perform(form, args)
        return OK

    def poll(self) -> Answer:
        return self._started

    def stop(self) -> Answer:
        self.device.line = self.line()
        try:
            self.device.stop()
        except DeviceError as error:
            return Answer(Status.ERROR, message=str(error))
        return OK

    def end(self) -> Answer:
        return OK  # a Device has nothing to do at the end: (END) leaves motion as it is

    @property
    def pending(self) -> LineLost | None:
        return self.device.pending

    def take_event(self) -> LineLost | None:
        return self.device.poll_event()
