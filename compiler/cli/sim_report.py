"""What `rl1c sim` prints: the calls with the vehicle's pose, how the run ended, the
final variables; in JSON also the pose track and the events, for tools."""

from __future__ import annotations

import json
import math

from rl1.compiler.frontend.source import Source
from rl1.vm.faults import RunResult
from rl1.vm.sim.device import RunOn, SimDevice, SimEntry
from rl1.vm.sim.motion import Pose

from .run_report import TraceChoice, fault_text, select_trace


def _pose(pose: Pose) -> list[float]:
    return [round(pose.x, 2), round(pose.y, 2), round(math.degrees(pose.heading), 2)]


def _ending(result: RunResult, device: SimDevice, run_on: RunOn | None, program: str,
            source: Source | None, color: bool) -> str:
    """How the run ended: where the vehicle ran on to after an (END) that left it moving,
    or the fault as `rl1c run` shows it."""
    fault = result.fault
    if fault is None:
        if run_on is None:
            return "the program ended normally"
        pose = device.sim.pose
        stop = (f"until a safety stop [{run_on.stop.kind}]: {run_on.stop}"
                if run_on.stop is not None else
                f"until it stopped at ({pose.x:.1f}, {pose.y:.1f})")
        return (f"the program ended normally with the vehicle moving: it ran on for "
                f"{run_on.seconds:.2f} s, {stop}")
    return fault_text(fault, program, source.name if source else program,
                      source.text if source else None, color=color).rstrip("\n")


def _entry_line(entry: SimEntry) -> str:
    call = entry.call + (" " + ",".join(map(str, entry.args)) if entry.args else "")
    if entry.result is not None:
        call += " -> " + " ".join(map(str, entry.result))
    pose = entry.pose
    return (f"  {entry.time:9.2f}  {call:<28} ({pose.x:7.1f}, {pose.y:7.1f}) "
            f"{math.degrees(pose.heading):6.1f}")


def render_text(result: RunResult, device: SimDevice, program: str, source: Source | None,
                run_on: RunOn | None = None, trace: TraceChoice = "short", *,
                color: bool = False) -> str:
    """The report for people of a run of `program` (`source`, when known), with the
    calls `trace` chooses (as `rl1c run --trace`)."""
    lines = []
    shown = select_trace(device.trace, trace)
    if shown.head:
        lines.append("trace (simulated time in s; pose x, y in cm, heading in degrees):")
        lines += shown.lines(_entry_line)
    for event in device.sim.events:
        if event.kind in ("lost", "handler", "found"):
            lines.append(f"  {event.time:9.2f}  [{event.text}]")
    lines.append(_ending(result, device, run_on, program, source, color))
    named = [f"{name}={value}" for name, value in result.named().items() if value]
    lines.append("variables: " + (" ".join(named) + " (all others 0)" if named else "all 0"))
    return "\n".join(lines) + "\n"


def render_json(result: RunResult, device: SimDevice, run_on: RunOn | None = None,
                trace: TraceChoice = "all") -> str:
    status = result.status()  # the shape of `rl1c run`'s, and a safety stop's facts
    if device.fault is not None:
        status |= {"safety": device.fault.kind, "time": round(device.fault.time, 4),
                   "pose": _pose(device.fault.pose)}
    shown = select_trace(device.trace, trace)
    document = {
        "status": status,
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
