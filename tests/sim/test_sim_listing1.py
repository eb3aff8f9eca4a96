"""Listing 1 replayed on the scene of Fig. 4 (examples/sample.world.toml) and on its
mirror image: the sequence is checked from the run's calls and poses, not against a
recorded trace."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from rl1.compiler.runner import Finished, run
from rl1.vm.defaults import Engine
from rl1.vm.faults import RunResult
from rl1.vm.sim.camera import focal, pulse_angle
from rl1.vm.sim.device import SimDevice, SimEntry
from rl1.vm.sim.geometry import segment_nearest
from rl1.vm.sim.world import World, decode_world

EXAMPLES = Path(__file__).parents[2] / "examples"
SAMPLE = (EXAMPLES / "sample.rob").read_text()


def _world(name: str) -> World:
    path = EXAMPLES / name
    return decode_world(path.read_bytes(), str(path))


def _run(world: World, engine: Engine = "vm") -> tuple[RunResult, SimDevice]:
    device = SimDevice(world)
    finished = run(SAMPLE, device, engine=engine)
    assert isinstance(finished, Finished)
    return finished.result, device


def _index(trace: list[SimEntry], call: str, args: tuple[int, ...] = (), start: int = 0) -> int:
    return next(i for i in range(start, len(trace))
                if trace[i].call == call and (not args or trace[i].args == args))


@pytest.mark.parametrize(("name", "side"), [("sample.world.toml", 1),
                                            ("sample.mirrored.world.toml", -1)])
def test_listing_1_runs_its_whole_sequence(name: str, side: int) -> None:
    world = _world(name)
    result, device = _run(world)
    assert result.fault is None
    trace = device.trace
    vehicle = world.vehicle
    (mark,) = world.marks
    (stand,) = world.stands
    view_ahead = vehicle.camera_ahead + vehicle.camera_height / math.tan(
        math.radians(vehicle.tilt_down))

    # 1. It traces the line and stops where the branch mark enters the view.
    stop = _index(trace, "MOV", (0, 0))
    areas = [e.result[0] for e in trace[:stop] if e.call == "IMG" and e.result]
    assert all(area < 180 for area in areas[:-1]) and areas[-1] >= 180
    mark_start = min(x for x, _ in mark.points)
    assert trace[stop].pose.x + view_ahead == pytest.approx(mark_start, abs=1.0)
    assert trace[stop].pose.y == pytest.approx(150, abs=0.5)

    # 2. Comparing scenes 4 and 3 tells the stand's side: it pans there.
    pan = _index(trace, "CAM P", start=stop)
    assert trace[pan].args == ((579,) if side > 0 else (205,))
    assert math.copysign(1, pulse_angle(trace[pan].args[0])) == side

    # 3. It centres the marker: five measurements, each on the image's centre column.
    steer = _index(trace, "STX", start=pan)
    centring = [e for e in trace[pan:steer] if e.call == "IMG"]
    assert len(centring) == 5
    assert all(e.result is not None and e.result[1] == 128 for e in centring)
    assert trace[steer].args == (450 * side,)

    # 4. It approaches until the marker's y passes 160, x staying in 60..200; the
    #    distance Fig. 3 reads from y is the one the vehicle is at.
    hold = _index(trace, "HLD", start=steer)
    approach = [e.result for e in trace[steer:hold] if e.call == "IMG" and e.result]
    ys = [r[2] for r in approach]
    assert ys[-1] > 160 >= max(ys[:-1])
    assert ys[0] < ys[len(ys) // 2] < ys[-2]  # moving down the image as it nears
    assert all(60 <= r[1] <= 200 for r in approach)
    pose = trace[hold].pose
    camera = (pose.x + vehicle.camera_ahead * math.cos(pose.heading),
              pose.y + vehicle.camera_ahead * math.sin(pose.heading))
    marker = stand.marker()
    distance = math.hypot(marker[0] - camera[0], marker[1] - camera[1])
    assert distance == pytest.approx(3 * focal(vehicle) / (ys[-1] - 120), rel=0.05)
    assert abs(pose.y - 150) > 50  # it left the line towards the stand
    assert math.copysign(1, pose.y - 150) == side

    # 5. It steers away, drives until it sees a line (area 100), steers back.
    found = _index(trace, "STR", (75,), start=hold)
    last_look = [e for e in trace[hold:found] if e.call == "IMG"][-1]
    assert last_look.result is not None and last_look.result[0] >= 100
    assert _index(trace, "STL", (75,), start=hold) < found

    # 6. It re-enters tracing and covers 50 cm without losing the line; then it ends.
    moved = _index(trace, "MVI", start=found)
    assert trace[moved - 1].call == "TRC" and trace[moved - 1].args == (3,)
    start, end = trace[moved - 1].pose, trace[moved].pose
    assert math.hypot(end.x - start.x, end.y - start.y) == pytest.approx(50, abs=1)
    assert not [e for e in device.sim.events if e.kind == "lost"]
    (line,) = [line for line in world.lines if line.name == "return"]
    view = device.sim.view()
    assert segment_nearest(view.x, view.y, *line.points)[2] < 60
    assert trace[-1].call == "FRE"


@pytest.mark.parametrize("name", ["sample.world.toml", "sample.mirrored.world.toml"])
def test_both_engines_drive_the_simulator_through_the_same_sequence(name: str) -> None:
    """The VM's instructions and the interpreter's statements take the interpreter's
    time (spec/simulator.md, "Time"), so their polls differ in number and their
    readings by a pixel; the calls, each poll counted once, are the same."""
    world = _world(name)
    ran = {engine: _run(world, engine) for engine in ("vm", "ast")}

    def sequence(device: SimDevice) -> list[tuple[str, tuple[int, ...], int | None]]:
        calls: list[tuple[str, tuple[int, ...], int | None]] = []
        for entry in device.trace:
            args = entry.args if entry.call != "CAM P" else ()  # the centring's pulses
            if not calls or calls[-1] != (entry.call, args, entry.line):
                calls.append((entry.call, args, entry.line))
        return calls

    (vm_result, vm_device), (ast_result, ast_device) = ran["vm"], ran["ast"]
    assert vm_result.fault is None and ast_result.fault is None
    assert sequence(vm_device) == sequence(ast_device)
    assert vm_device.sim.pose.x == pytest.approx(ast_device.sim.pose.x, abs=5)
    assert vm_device.sim.pose.y == pytest.approx(ast_device.sim.pose.y, abs=5)


def test_halving_the_step_leaves_listing_1_where_it_was() -> None:
    world = _world("sample.world.toml")
    ends = []
    for step in (0.05, 0.025):
        device = SimDevice(world, step=step)
        finished = run(SAMPLE, device)
        assert isinstance(finished, Finished) and finished.result.fault is None
        ends.append(device.sim.pose)
    assert math.hypot(ends[0].x - ends[1].x, ends[0].y - ends[1].y) < 1.0
    assert ends[0].heading == pytest.approx(ends[1].heading, abs=1e-6)
