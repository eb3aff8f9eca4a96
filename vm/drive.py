"""Stepping a VM on a device whose clock the stepper moves between calls.

On the scripted device, with the losses its script times by instruction count: what
`rl1c run` and the test vectors do. The scripted device's clock moves only inside calls,
so a loss "after instruction N" (scripted.LossAfter) is the stepper's to make: it steps
the VM to exactly N instructions and loses the line there, between two instructions, as
a vehicle's device posts a loss from an interrupt (spec/ilc.md, section 12.4).

On a device whose time runs with the instructions (`Clocked`: the simulator, where each
instruction takes the interpreter's time): the stepper lets that time pass between steps
too, so that the world moves on in a loop that makes no call.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol, runtime_checkable

from .device import DeviceError
from .faults import Fault, FaultKind, RunResult
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

    @property
    def variables(self) -> Sequence[int]: ...

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


@runtime_checkable
class Clocked(Protocol):
    """A device on which each instruction the engine runs takes time (vm/sim/device.py)."""

    line: int | None

    def count_instructions(self, executed: Callable[[], int]) -> None: ...

    @property
    def slice(self) -> int: ...

    def catch_up(self) -> None: ...

    def stop(self) -> None: ...


def drive_clocked(machine: Stepper, device: Clocked) -> RunResult:
    """Run `machine`, whose hardware is `device`, to its end, letting the time of its
    instructions pass at least every `device.slice` instructions. A safety stop between
    calls is the device's fault at the instruction run last, as it would be in a call."""
    device.count_instructions(lambda: machine.executed)
    while machine.step(device.slice) in _GOING:
        try:
            device.catch_up()
        except DeviceError as error:
            device.line = line = machine.current_line()
            device.stop()
            return RunResult(tuple(machine.variables), Fault(FaultKind.DEVICE, str(error), line))
    return machine.run()
