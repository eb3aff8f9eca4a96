"""Run-time faults and the outcome of a run, shared by the interpreter and the VM.

A fault ends a run: the engine first stops the vehicle (Device.stop), then reports the
fault with the source line it happened on. Each kind has its own exit status for
`rl1c run` (1 and 2 are taken: "the program has errors" and "usage or unreadable file").
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import Any

from .defaults import DEFAULT_BUDGET as DEFAULT_BUDGET  # the engines' default, named here too
from .language import VARIABLES

MAX_BUDGET = 2**31 - 1
"""The largest budget: a run passes its budget by less than 65536 instructions (spec/ilc.md,
section 9), so a 32-bit counter never wraps."""


class FaultKind(Enum):
    """A kind of fault: its name in JSON and the vectors (`code`), the exit status of
    `rl1c run` and `rl1c sim`, and its code in the catalogue of `rl1c explain` (E10xx,
    xx the exit status), which the report of a fault shows as a diagnostic's."""

    ARGUMENT_RANGE = ("argument-range", 10, "E1010")  # a variable argument outside its range
    MISSING_HANDLER = ("missing-handler", 11, "E1011")  # a lost line jumps to an undefined :96-:99
    BUDGET = ("budget", 12, "E1012")  # the watchdog: the step budget is used up
    DEVICE = ("device-error", 13, "E1013")  # the device failed (DeviceError)
    ABORTED = ("aborted", 14, "E1014")  # the firmware's emergency stop (Machine.abort)

    def __init__(self, code: str, exit_status: int, diagnostic_code: str) -> None:
        self.code = code
        self.exit_status = exit_status
        self.diagnostic_code = diagnostic_code


@dataclass(frozen=True, slots=True)
class Fault:
    kind: FaultKind
    message: str
    line: int | None  # the source line, when known


@dataclass(frozen=True, slots=True)
class RunResult:
    """The final variables (53, in language.VARIABLES order) and the fault that ended
    the run, None when it ended normally."""

    variables: tuple[int, ...]
    fault: Fault | None = None

    def named(self) -> dict[str, int]:
        return dict(zip(VARIABLES, self.variables, strict=True))

    def status(self) -> dict[str, Any]:
        """How the run ended, as JSON data in one shape whether it ended or faulted:
        `code` ("ok" or the fault's kind), the exit status of `rl1c run`, a message, and
        the fault's source line (None when it ended, or when unknown)."""
        fault = self.fault
        if fault is None:
            return {"code": "ok", "exit_status": 0, "message": "the program ended",
                    "line": None}
        return {"code": fault.kind.code, "exit_status": fault.kind.exit_status,
                "message": fault.message, "line": fault.line}


def missing_handler_message(mode: int, command: str, label: int) -> str:
    """What a MISSING_HANDLER fault says, whichever engine meets it."""
    return (f"the line was lost during {command} in tracing mode {mode}, which jumps to "
            f":{label}, but the program has no label :{label}")


def budget_message(budget: int, steps: str = "instructions") -> str:
    """What a BUDGET fault says, whichever engine meets it: `steps` names what it counts
    (the VMs' instructions, the interpreter's statements). What to do is its help's."""
    return f"the program ran more than {budget} {steps} without ending"


def argument_range_message(param: str, form: str, value: int, variable: int, low: int,
                           high: int) -> str:
    """What an ARGUMENT_RANGE fault of the VM says: parameter `param` of built-in `form`
    got `value` from the variable of index `variable`."""
    return (f"argument {param} of ({form}) is {value} (the value of {VARIABLES[variable]}), "
            f"outside {low}..{high}")


ABORTED_MESSAGE = "the run was aborted from outside the program (an emergency stop)"
"""What an ABORTED fault says, whichever VM meets it."""


STOP_FAILED = "; stopping the vehicle failed too: "
"""What a fault's message gains when stopping the vehicle failed, before the reason."""
