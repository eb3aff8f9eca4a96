"""Running a program on the scripted device, with the losses its script times by
instruction count: what `rl1c run` and the test vectors do.

The scripted device's clock moves only inside calls, so a loss "after instruction N"
(scripted.LossAfter) is the stepper's to make: it steps the VM to exactly N instructions
and loses the line there, between two instructions, as a vehicle's device posts a loss
from an interrupt (spec/ilc.md, section 12.4).
"""

from __future__ import annotations

from typing import Protocol

from .faults import RunResult
from .machine import State
from .scripted import ScriptedDevice

_GOING = (State.RUNNING, State.WAITING)


class Stepper(Protocol):
    """A VM run stepped as spec/ilc.md section 12 says: machine.Machine, or the C VM's
    native.NativeMachine."""

    @property
    def executed(self) -> int: ...

    @property
    def state(self) -> State: ...

    def step(self, limit: int) -> State: ...

    def run(self) -> RunResult: ...

    def current_line(self) -> int | None: ...


def drive(machine: Stepper, device: ScriptedDevice) -> RunResult:
    """Run `machine`, whose hardware is `device`, to its end."""
    for count in device.script.instruction_losses:
        while machine.executed < count and machine.step(count - machine.executed) in _GOING:
            pass
        if machine.state not in _GOING:
            break
        device.lose_line_after(count, machine.current_line())
    return machine.run()
