"""What `rl1c sim` prints: the calls with the vehicle's pose, how the run ended, the
final variables; in JSON also the pose track and the events, for tools."""

from __future__ import annotations

import json
import math

from rl1.vm.faults import RunResult
from rl1.vm.sim.device import RunOn, SimDevice
from rl1.vm.sim.motion import Pose


def _pose(pose: Pose) -> list[float]:
    return [round(pose.x, 2), round(pose.y, 2), round(math.degrees(pose.heading), 2)]


def _ending(result: RunResult, device: SimDevice, run_on: RunOn | None) -> str:
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
    where = f" at line {fault.line}" if fault.line is not None else ""
    return f"fault[{fault.kind.code}]{where}: {fault.message}"


def render_text(result: RunResult, device: SimDevice, run_on: RunOn | None = None) -> str:
    lines = ["trace (simulated time in s; pose x, y in cm, heading in degrees):"]
    for entry in device.trace:
        call = entry.call + (" " + ",".join(map(str, entry.args)) if entry.args else "")
        if entry.result is not None:
            call += " -> " + " ".join(map(str, entry.result))
        pose = entry.pose
        lines.append(f"  {entry.time:9.2f}  {call:<28} ({pose.x:7.1f}, {pose.y:7.1f}) "
                     f"{math.degrees(pose.heading):6.1f}")
    for event in device.sim.events:
        if event.kind in ("lost", "handler", "found"):
            lines.append(f"  {event.time:9.2f}  [{event.text}]")
    lines.append(_ending(result, device, run_on))
    named = [f"{name}={value}" for name, value in result.named().items() if value]
    lines.append("variables: " + (" ".join(named) + " (all others 0)" if named else "all 0"))
    return "\n".join(lines) + "\n"


def render_json(result: RunResult, device: SimDevice, run_on: RunOn | None = None) -> str:
    status = "ok" if result.fault is None else result.fault.to_json()
    if device.fault is not None:
        status = {**(status if isinstance(status, dict) else {}),
                  "safety": device.fault.kind, "time": round(device.fault.time, 4),
                  "pose": _pose(device.fault.pose)}
    document = {
        "status": status,
        "variables": result.named(),
        # After an (END) with the vehicle moving: how long it ran on, and what stopped it.
        "run_on": None if run_on is None else {
            "seconds": round(run_on.seconds, 4), "pose": _pose(device.sim.pose),
            "stop": None if run_on.stop is None else run_on.stop.kind},
        "trace": [entry.to_json() for entry in device.trace],
        "events": [{"time": round(e.time, 4), "kind": e.kind, "text": e.text,
                    "pose": [round(e.pose.x, 2), round(e.pose.y, 2)]}
                   for e in device.sim.events],
        "track": [[round(t, 4), round(p.x, 2), round(p.y, 2), round(math.degrees(p.heading), 2)]
                  for t, p in device.sim.track],
    }
    return json.dumps(document, indent=1) + "\n"
