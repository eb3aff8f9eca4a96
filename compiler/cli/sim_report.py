"""What `rl1c sim` prints: the calls with their device time, source line and the
vehicle's pose after each, how the run ended, and last, as `rl1c run` ends, the final
variables, the device time and the instructions run (run_report.py); in JSON also the
pose track and the events, for tools."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from rl1.compiler.simulation import run_status
from rl1.vm.defaults import TraceChoice
from rl1.vm.faults import FaultKind, RunResult
from rl1.vm.scripted import LOST
from rl1.vm.sim.device import RunOn, SimDevice, SimEntry
from rl1.vm.sim.goal import Verdict
from rl1.vm.sim.motion import Pose, heading_degrees
from rl1.vm.sim.simulator import Event

from .run_report import (
    TRACE_HEADING,
    call_text,
    closing_lines,
    entry_start,
    fault_text,
    select_trace,
)
from .running import Ran


def _pose(pose: Pose) -> list[float]:
    return [round(pose.x, 2), round(pose.y, 2), heading_degrees(pose.heading, 2)]


def _ms(seconds: float) -> int:
    """Simulated time as the reports give device time: whole milliseconds."""
    return round(seconds * 1000)


_SAFETY_HELP = {
    "collision": "see where with --svg FILE (a top view of the path, the walls and the stop); "
                 "stop or turn before it: read the distance ahead (`A=(ULT A)`), count the "
                 "distance driven (`(KYO)`, `(MVI l,r,cm)`), or trace a line in mode 2",
    "off-floor": "see where with --svg FILE (a top view of the path and the floor); stop or "
                 "turn before the edge: count the distance driven (`(KYO)`, `(MVI l,r,cm)`) "
                 "or trace a line in mode 2; or make the world's floor larger ([floor] size)",
    "time-limit": "if the program should run longer, raise the world's [limits] time; if "
                  "not, it waits for something that does not come: --svg FILE shows where "
                  "the vehicle was",
}
_SIMULATED_DEVICE_HELP = ("the simulated vehicle cannot do what the call asks; "
                          "spec/simulator.md says what each call does (\"Motion\")")


def _help(device: SimDevice, kind: FaultKind) -> str | None:
    """What to do about a fault of the kind `kind` in the simulator: a safety stop's
    own words, or None for the words of `rl1c run` (a fault of the program)."""
    if device.fault is not None:
        return _SAFETY_HELP[device.fault.kind]
    return _SIMULATED_DEVICE_HELP if kind is FaultKind.DEVICE else None


def _ending(ran: Ran, device: SimDevice, run_on: RunOn | None, program: str,
            color: bool) -> str:
    """How the run ended: where the vehicle ran on to after an (END) that left it moving,
    or the fault as `rl1c run` shows it."""
    fault = ran.finished.result.fault
    if fault is None:
        if run_on is None:
            return "the program ended normally"
        pose = device.sim.pose
        stop = (f"until a safety stop [{run_on.stop.kind}]: {run_on.stop}"
                if run_on.stop is not None else
                f"until it stopped at ({pose.x:.1f}, {pose.y:.1f})")
        return (f"the program ended normally with the vehicle moving: it ran on for "
                f"{run_on.seconds:.2f} s, {stop}")
    return fault_text(fault, program, ran.source_name, ran.source, color=color,
                      help=_help(device, fault.kind)).rstrip("\n")


def _goal_lines(verdict: Verdict) -> list[str]:
    """The verdict's headline, then each part: met or missed, and what happened."""
    return [verdict.headline(), *(f"- {outcome.title()}: {'met' if outcome.met else 'MISSED'}"
                                  f", {outcome.text}" for outcome in verdict.outcomes)]


LINE_EVENTS = ("lost", "handler", "found")
"""The simulator's events that the trace shows among the calls."""


@dataclass(frozen=True, slots=True)
class _LineEvent:
    """A lost or found line, or a handler taken, as a row of the trace: its `call` is
    the scripted device's lost line, so that `--trace calls` leaves it out as `rl1c run`
    leaves out its lost lines, and `--trace short` counts it as an entry."""

    event: Event
    call: str = LOST


def _time(row: SimEntry | _LineEvent) -> float:
    return row.event.time if isinstance(row, _LineEvent) else row.time


def _rows(device: SimDevice) -> list[SimEntry | _LineEvent]:
    """The calls and the line events in the order of their time (a call first when both
    have the same: a loss happens during the call under way)."""
    events = [_LineEvent(event) for event in device.sim.events if event.kind in LINE_EVENTS]
    return sorted([*device.trace, *events], key=_time)  # stable: the calls first


def _entry_line(row: SimEntry | _LineEvent) -> str:
    if isinstance(row, _LineEvent):
        return f"{entry_start(_ms(row.event.time), None)}[{row.event.text}]"
    pose = row.pose
    return (entry_start(_ms(row.time), row.line)
            + f"{call_text(row.call, row.args, row.result):<40} "
            f"({pose.x:7.1f}, {pose.y:7.1f}) {heading_degrees(pose.heading, 1):6.1f}")


def render_text(ran: Ran, device: SimDevice, program: str, ended_at: float,
                run_on: RunOn | None = None, trace: TraceChoice = "short", *,
                color: bool = False, verdict: Verdict | None = None) -> str:
    """The report for people of the run `ran` of `program`, which ended at simulated
    time `ended_at` (s), with the calls `trace` chooses (as `rl1c run --trace`), and
    the goal's `verdict` when the world has a goal."""
    lines = []
    shown = select_trace(_rows(device), trace)
    if shown.head:
        lines.append(f"{TRACE_HEADING:<58} pose after it: x, y (cm), heading (degrees)")
        lines += shown.lines(_entry_line)
    lines.append(_ending(ran, device, run_on, program, color))
    if verdict is not None:
        lines += _goal_lines(verdict)
    lines += closing_lines(ran.finished.result, _ms(ended_at), ran.finished.instructions)
    return "\n".join(lines) + "\n"


def render_json(result: RunResult, device: SimDevice, instructions: int | None,
                ended_at: float, run_on: RunOn | None = None,
                trace: TraceChoice = "all", verdict: Verdict | None = None) -> str:
    status = run_status(result, verdict)  # the shape of `rl1c run`'s, and a safety stop's
    if device.fault is not None:
        status |= {"safety": device.fault.kind, "time": round(device.fault.time, 4),
                   "pose": _pose(device.fault.pose)}
    shown = select_trace(device.trace, trace)
    document: dict[str, Any] = {
        "status": status,
        "instructions": instructions,  # as `rl1c run`'s: None when the interpreter ran it
        "device_time": _ms(ended_at),  # ms, as `rl1c run`'s
        "variables": result.named(),
        "goal": None if verdict is None else verdict.to_json(),  # null: the world has none
        # After an (END) with the vehicle moving: how long it ran on, and what stopped it.
        "run_on": None if run_on is None else {
            "seconds": round(run_on.seconds, 4), "pose": _pose(device.sim.pose),
            "stop": None if run_on.stop is None else run_on.stop.kind},
        "trace": [entry.to_json() for entry in (*shown.head, *shown.tail)],
        "trace_left_out": ({"after": len(shown.head), "count": shown.left_out}
                           if shown.left_out else None),
        "events": [{"time": round(e.time, 4), "kind": e.kind, "text": e.text,
                    "pose": [round(e.pose.x, 2), round(e.pose.y, 2)]}
                   for e in device.sim.events],
        "track": [[round(t, 4), round(p.x, 2), round(p.y, 2), heading_degrees(p.heading, 2)]
                  for t, p in device.sim.track],
    }
    return json.dumps(document, indent=1) + "\n"
