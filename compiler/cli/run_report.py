"""What `rl1c run` prints: the device's trace (bounded, or chosen by --trace), how the
run ended (a fault shown as the checker shows a diagnostic, with its source line and the
call underlined), whether the vehicle still moves, the final variables, and last the
device time and the instructions run; or all of it as one JSON object (spec/sensors.md,
"The report in JSON"). `rl1c sim`'s report (sim_report.py) shares its trace's bounds,
its calls' text, its faults and its last lines."""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, Protocol, TypeVar

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.reporting.render import FileDiagnostics, diagnostic_blocks
from rl1.vm.defaults import TraceChoice
from rl1.vm.device import READING_NAMES
from rl1.vm.faults import Fault, FaultKind, RunResult
from rl1.vm.scripted import LOST, TraceEntry
from rl1.vm.sensor_script import LossAfter, LossAt, LossDuring

HEAD = 40
TAIL = 20
"""A short trace shows its first HEAD and last TAIL entries, and how many it left out
between them; a trace that would leave out only one entry is shown whole."""


class Traced(Protocol):
    """A trace entry of either device: the scripted one's, or the simulator's."""

    @property
    def call(self) -> str: ...


Entry = TypeVar("Entry", bound=Traced)


@dataclass(frozen=True, slots=True)
class ShownTrace(Generic[Entry]):
    """The entries a report shows: `head`, then `left_out` entries not shown, then `tail`."""

    head: Sequence[Entry]
    left_out: int = 0
    tail: Sequence[Entry] = ()

    def lines(self, line_of: Callable[[Entry], str]) -> list[str]:
        """The entries as text, a line each (`line_of`), with a line saying how many were
        left out where they were."""
        lines = [line_of(entry) for entry in self.head]
        if self.left_out:
            lines.append(f"{'...':>9}  ({self.left_out:,} entries left out: --trace all "
                         "shows every one)")
            lines += [line_of(entry) for entry in self.tail]
        return lines


def select_trace(log: Sequence[Entry], choice: TraceChoice) -> ShownTrace[Entry]:
    """What `--trace` shows of a run's log: all of it, its calls alone (no lost lines, no
    stop after a fault), nothing, or (short) its head and tail."""
    if choice == "none":
        return ShownTrace(())
    if choice == "calls":
        return ShownTrace([entry for entry in log if entry.call not in (LOST, "STOP")])
    if choice == "all" or len(log) <= HEAD + TAIL + 1:
        return ShownTrace(log)
    return ShownTrace(log[:HEAD], len(log) - HEAD - TAIL, log[len(log) - TAIL:])


@dataclass(frozen=True, slots=True)
class RunReport:
    """Everything a report of a run says. `source` is the program's text, when known (a
    .rob file, or the source an .ilc file records and that is still the one compiled)."""

    name: str  # the program's file, as given
    source_name: str  # the file whose lines `source` holds
    source: str | None
    result: RunResult
    trace: ShownTrace[TraceEntry]
    instructions: int | None  # None when the interpreter ran it
    device_time: int  # ms
    moving: str | None  # the motion in effect when the program ended: "(MOV 3,3)"
    missed: Sequence[tuple[int, LossAt | LossDuring | LossAfter, str]] = ()
    """The script's losses that never happened: index in line_lost, loss, why."""


# Text ---------------------------------------------------------------------------------


def render_text(report: RunReport, *, color: bool = False) -> str:
    lines = []
    trace = report.trace
    if trace.head:
        lines.append(TRACE_HEADING)
        lines += trace.lines(_entry_line)
    fault = report.result.fault
    if fault is None:
        lines.append("the program ended normally")
        if report.moving is not None:
            lines.append(f"note: the program ended with {report.moving} in effect: the "
                         "vehicle is still moving")
    else:
        lines.append(fault_text(fault, report.name, report.source_name, report.source,
                                color=color).rstrip("\n"))
    lines += [f"note: the sensor script's line_lost[{index}], {json.dumps(loss.to_json())}, "
              f"never happened: {why}" for index, loss, why in report.missed]
    lines += closing_lines(report.result, report.device_time, report.instructions)
    return "\n".join(lines) + "\n"


TRACE_HEADING = f"{'time ms':>9}  {'line':>4}  call"
"""The trace's heading, in both reports: each call at the device time it was made."""


def entry_start(time_ms: int, line: int | None) -> str:
    """A trace line's first columns, in both reports: the time and the source line."""
    return f"{time_ms:>9}  {line if line is not None else '-':>4}  "


def call_text(call: str, args: Sequence[int], result: Sequence[int] | None) -> str:
    """A call as both reports show it: `MOV 3,3`, `ULT B -> 40`, and the values of a
    reading of several named (`IMG -> area 120, x 128, y 90, angle 0`)."""
    text = call + (" " + ",".join(map(str, args)) if args else "")
    if result is not None:
        names = READING_NAMES.get(call)
        text += " -> " + (", ".join(f"{name} {value}" for name, value
                                    in zip(names, result, strict=True))
                          if names is not None else " ".join(map(str, result)))
    return text


def _entry_line(entry: TraceEntry) -> str:
    shown = entry.describe() if entry.call == LOST else call_text(entry.call, entry.args,
                                                                  entry.result)
    return entry_start(entry.time, entry.line) + shown


def closing_lines(result: RunResult, device_time: int, instructions: int | None
                  ) -> list[str]:
    """How both reports end: the final variables, then the device time (ms) and the
    instructions the VM ran (the interpreter counts none)."""
    named = [f"{name}={value}" for name, value in result.named().items() if value]
    executed = ("the interpreter counts no instructions" if instructions is None else
                f"{instructions:,} instruction{'s' if instructions != 1 else ''}")
    return ["variables: " + (" ".join(named) + " (all others 0)" if named else "all 0"),
            f"{device_time} ms of device time, {executed}"]


# A fault as a diagnostic ---------------------------------------------------------------

_HELP = {
    FaultKind.ARGUMENT_RANGE: "test the variable before the call (`?V<#NN`, `?V>#NN`), or "
                              "compute it so that it stays in the range",
    FaultKind.MISSING_HANDLER: "add the handler label the message names, to say what the "
                               "vehicle does when it loses the line (`rl1c explain W0301`)",
    FaultKind.BUDGET: "if the program should run longer, raise --budget; if not, this jump "
                      "closes a loop that nothing ends",
    FaultKind.DEVICE: "the vehicle refused or failed the call; on the scripted device, the "
                      "sensor script decides readings and failures (spec/sensors.md)",
    FaultKind.ABORTED: "the firmware's emergency stop ended the run; the program did "
                       "nothing wrong",
}
_TIME_LIMIT_HELP = ("if the program should run longer, raise --time-limit; if not, it waits "
                    "in a loop for something that does not come")
_NO_READING_HELP = ("add readings to the sensor script (spec/sensors.md), or set its "
                    "after_last to \"repeat\" to repeat the last one")  # in JSON or TOML
_NO_SCRIPT_HELP = ("give the readings the program needs in a sensor script: "
                   "--sensors FILE (spec/sensors.md)")
_FORM = re.compile(r"\(([A-Z]{3})\b")
_NO_HANDLER = re.compile(r"has no label :(\d\d)")  # as faults.missing_handler_message says


def _handler_help(label: str) -> str:
    """What to do about a lost line that jumps to the missing handler `:label`, in the
    words of the checker's W0301."""
    return (f"add the handler label: a line that starts with `:{label}` and says what the "
            f"vehicle does when it loses the line, e.g. `:{label} (MOV 0,0); (END)` "
            "(`rl1c explain W0301`)")


def fault_help(fault: Fault) -> str:
    """What to do about `fault`."""
    if fault.kind is FaultKind.DEVICE:
        if "device-time limit" in fault.message:
            return _TIME_LIMIT_HELP
        if "no sensor script was given" in fault.message:
            return _NO_SCRIPT_HELP
        if "has no reading" in fault.message:
            return _NO_READING_HELP
    if fault.kind is FaultKind.MISSING_HANDLER and (
            label := _NO_HANDLER.search(fault.message)) is not None:
        return _handler_help(label.group(1))
    return _HELP[fault.kind]


def fault_text(fault: Fault, name: str, source_name: str, text: str | None, *,
               color: bool = False, help: str | None = None) -> str:
    """The fault of a run of the program `name` as the checker shows a diagnostic:
    `error[E1010]: message`, `--> file:line:col`, the source line (of `text`, the
    file `source_name`, when known) with the call underlined, and what to do (`help`,
    or what `fault_help` says)."""
    lines = text.splitlines() if text is not None else []
    message = fault.message
    if fault.line is not None and 1 <= fault.line <= len(lines):
        found = fault_span(lines[fault.line - 1], fault)
        span = Span(fault.line, found.column, fault.line, found.end_column)
        shown = FileDiagnostics(source_name, text, [])
    else:  # no source to show: the line, if known, goes into the message
        span = Span(1, 1, 1, 1)
        if fault.line is not None:
            message += f" (at line {fault.line})"
        shown = FileDiagnostics(name, None, [])
    diagnostic = Diagnostic(fault.kind.diagnostic_code, Severity.ERROR, message, span,
                            help=help or fault_help(fault))
    return diagnostic_blocks(FileDiagnostics(shown.name, shown.text, [diagnostic]),
                             color=color)


def fault_span(line: str, fault: Fault) -> Span:
    """Where on its source line (numbered 1 here) `fault` happened: the call it names
    (`(MOV)` in its message), else the jump for a fault taken at a jump, else the line's
    first call, else the whole line."""
    program, _ = parse_program(line)
    nodes = list(ast.walk(program))
    calls = [node for node in nodes if isinstance(node, ast.Call)]
    jumps = [node for node in nodes if isinstance(node, ast.Goto | ast.CondJump)]
    named = _FORM.search(fault.message)
    if named is not None:
        for call in calls:
            if call.mnemonic.upper() == named.group(1):
                return call.span
    if jumps and (fault.kind in (FaultKind.BUDGET, FaultKind.MISSING_HANDLER) or not calls):
        return jumps[-1].span
    if calls:
        return calls[0].span
    code = line.split("'")[0].rstrip()
    start = len(code) - len(code.lstrip())
    return Span(1, start + 1, 1, max(len(code), start + 1) + 1)


# JSON ---------------------------------------------------------------------------------


def entry_json(entry: TraceEntry) -> dict[str, Any]:
    """A trace entry as the report writes it: as the vectors do, with its source line,
    and for a lost line what it did (`effect`) and the handler it jumped to."""
    document = entry.to_json()
    document["line"] = entry.line
    if entry.call == LOST:
        document["during"] = entry.during
        document["effect"] = entry.effect
        document["handler"] = entry.handler
    return document


def render_json(report: RunReport) -> str:
    trace = report.trace
    document = {
        "status": report.result.status(),
        "instructions": report.instructions,
        "device_time": report.device_time,
        "moving": report.moving,
        "variables": report.result.named(),
        "trace": [entry_json(entry) for entry in (*trace.head, *trace.tail)],
        "trace_left_out": ({"after": len(trace.head), "count": trace.left_out}
                           if trace.left_out else None),
        "losses_not_met": [{"index": index, "loss": loss.to_json(), "why": why}
                           for index, loss, why in report.missed],
    }
    return json.dumps(document, indent=2) + "\n"

