"""What `rl1c sim` prints: the calls with their device time, source line and the
vehicle's pose after each, how the run ended, and last, as `rl1c run` ends, the final
variables, the device time and the instructions run (run_report.py); in JSON also the
pose track and the events, for tools."""

from __future__ import annotations

import json
import math
from typing import Any

from rl1.vm.defaults import TraceChoice
from rl1.vm.faults import RunResult
from rl1.vm.sim.device import RunOn, SimDevice, SimEntry
from rl1.vm.sim.motion import Pose

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
    return [round(pose.x, 2), round(pose.y, 2), round(math.degrees(pose.heading), 2)]


def _ms(seconds: float) -> int:
    """Simulated time as the reports give device time: whole milliseconds."""
    return round(seconds * 1000)


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
    return fault_text(fault, program, ran.source_name, ran.source, color=color).rstrip("\n")


def _entry_line(entry: SimEntry) -> str:
    pose = entry.pose
    return (entry_start(_ms(entry.time), entry.line)
            + f"{call_text(entry.call, entry.args, entry.result):<40} "
            f"({pose.x:7.1f}, {pose.y:7.1f}) {math.degrees(pose.heading):6.1f}")


def render_text(ran: Ran, device: SimDevice, program: str, ended_at: float,
                run_on: RunOn | None = None, trace: TraceChoice = "short", *,
                color: bool = False) -> str:
    """The report for people of the run `ran` of `program`, which ended at simulated
    time `ended_at` (s), with the calls `trace` chooses (as `rl1c run --trace`)."""
    lines = []
    shown = select_trace(device.trace, trace)
    if shown.head:
        lines.append(f"{TRACE_HEADING:<58} pose after it: x, y (cm), heading (degrees)")
        lines += shown.lines(_entry_line)
    for event in device.sim.events:
        if event.kind in ("lost", "handler", "found"):
            lines.append(f"{entry_start(_ms(event.time), None)}[{event.text}]")
    lines.append(_ending(ran, device, run_on, program, color))
    lines += closing_lines(ran.finished.result, _ms(ended_at), ran.finished.instructions)
    return "\n".join(lines) + "\n"


def render_json(result: RunResult, device: SimDevice, instructions: int | None,
                ended_at: float, run_on: RunOn | None = None,
                trace: TraceChoice = "all") -> str:
    status = result.status()  # the shape of `rl1c run`'s, and a safety stop's facts
    if device.fault is not None:
        status |= {"safety": device.fault.kind, "time": round(device.fault.time, 4),
                   "pose": _pose(device.fault.pose)}
    shown = select_trace(device.trace, trace)
    document: dict[str, Any] = {
        "status": status,
        "instructions": instructions,  # as `rl1c run`'s: None when the interpreter ran it
        "device_time": _ms(ended_at),  # ms, as `rl1c run`'s
        "variables": result.named(),
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
        "track": [[round(t, 4), round(p.x, 2), round(p.y, 2), round(math.degrees(p.heading), 2)]
                  for t, p in device.sim.track],
    }
    return json.dumps(document, indent=1) + "\n"
