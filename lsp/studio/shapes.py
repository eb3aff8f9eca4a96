"""The data the page draws and inserts, as spec/studio.md's JSON shapes: a world's static
geometry (vm/sim/world.py), the built-ins palette (vm/language.py), a world file's
problems, a program's diagnostics. The page keeps no second copy of any of them."""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from typing import Any

from rl1.compiler.frontend.diagnostics import Diagnostic
from rl1.compiler.reporting.render import FileDiagnostics, report
from rl1.vm.device import READING_NAMES
from rl1.vm.language import BUILTINS, Builtin, Form
from rl1.vm.sim.geometry import Point
from rl1.vm.sim.goal import Region
from rl1.vm.sim.world import World

_LINE = re.compile(r"^.*?:(\d+): ")


def geometry(world: World) -> dict[str, Any]:
    """What the top view draws of `world`: everything but the vehicle's run."""
    goal = world.goal
    return {
        "floor": list(world.floor),
        "start": list(world.start),
        "vehicle": {"length": world.vehicle.length, "width": world.vehicle.width,
                    "cameraAhead": world.vehicle.camera_ahead},
        "lines": [{"name": line.name, "points": _points(line.points), "width": line.width}
                  for line in world.lines],
        "marks": [{"name": mark.name, "points": _points(mark.points)} for mark in world.marks],
        "stands": [{"name": stand.name, "corners": _points(stand.corners()),
                    "marker": list(stand.marker()), "facing": stand.facing}
                   for stand in world.stands],
        "walls": [{"name": block.name, "points": _points(block.points)}
                  for block in world.blocks if block.kind == "wall"],
        "obstacles": [{"name": block.name, "points": _points(block.points)}
                      for block in world.blocks if block.kind == "obstacle"],
        "goal": None if goal is None else {
            "reach": [_region(region) for region in goal.reach],
            "holds": [{"stand": hold.stand, "marker": list(hold.marker),
                       "within": hold.within} for hold in goal.holds],
            "end": None if goal.end is None else _region(goal.end),
            "avoid": [_region(region) for region in goal.avoid],
            "deadline": goal.deadline,
        },
    }


def _points(points: Sequence[Point]) -> list[list[float]]:
    return [[x, y] for x, y in points]


def _region(region: Region) -> dict[str, Any]:
    return {"name": region.name, "points": _points(region.points)}


def config_problem(message: str) -> dict[str, Any]:
    """A world file's or sensor script's problem, `file:line: key.path: what; what to
    write` (vm/config.py), with its line."""
    line = _LINE.match(message)
    return {"line": int(line[1]) if line else None, "message": message}


def palette() -> list[dict[str, Any]]:
    """Every built-in with its forms and their parameters, in vm/language.py's order."""
    return [_builtin(builtin) for builtin in BUILTINS.values()]


def _builtin(builtin: Builtin) -> dict[str, Any]:
    return {"mnemonic": builtin.mnemonic, "name": builtin.name, "group": builtin.group,
            "waits": builtin.waits, "readings": list(READING_NAMES.get(builtin.mnemonic, ())),
            "forms": [_form(builtin.mnemonic, form) for form in builtin.forms]}


def _form(mnemonic: str, form: Form) -> dict[str, Any]:
    words = " ".join([mnemonic] + ([form.selector] if form.selector else []))
    stops = ",".join(f"${{{index}:{param.name}}}"
                     for index, param in enumerate(form.params, start=1))
    return {"selector": form.selector, "summary": form.summary,
            "params": [param._asdict() for param in form.params],
            "result": form.result, "writes": list(form.writes),
            "snippet": f"({words}{' ' + stops if stops else ''})"}


def diagnostics(name: str, text: str, found: Sequence[Diagnostic]) -> list[dict[str, Any]]:
    """A program's diagnostics as `rl1c check --format json` writes them."""
    shown: list[dict[str, Any]] = json.loads(report([FileDiagnostics(name, text, found)],
                                                    "json"))
    return shown
