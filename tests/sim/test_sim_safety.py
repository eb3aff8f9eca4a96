"""Safety stops: leaving the floor, hitting a stand or a wall, the time limit. Each stops
the vehicle first and says which, where and when; the engine adds the source line."""

from __future__ import annotations

from dataclasses import replace

import pytest
from support.worlds import open_floor, stand_world

from rl1.compiler.runner import Finished, run
from rl1.vm.faults import FaultKind, RunResult
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.world import Block, World


def _run(world: World, text: str) -> tuple[RunResult, SimDevice]:
    device = SimDevice(world)
    finished = run(text, device)
    assert isinstance(finished, Finished)
    return finished.result, device


def test_leaving_the_floor_stops_the_run_at_its_line() -> None:
    result, device = _run(open_floor(), "(MOV 12,12)\n(TIM 100)\n(END)\n")
    assert result.fault is not None and result.fault.kind is FaultKind.DEVICE
    assert result.fault.line == 2
    assert "off-floor" in result.fault.message
    fault = device.fault
    assert fault is not None and fault.kind == "off-floor"
    # The front reaches x = 1000 when the centre is at 960: 460 cm at 60 cm/s.
    assert fault.time == pytest.approx(460 / 60, abs=0.05)
    assert fault.pose.x == pytest.approx(960, abs=3.1)
    assert device.sim.motion is None and device.trace[-1].call == "STOP"


def test_hitting_a_stand_is_a_collision() -> None:
    result, device = _run(stand_world(100), "(MVI 4,4,200)\n(END)\n")
    assert result.fault is not None and result.fault.line == 1
    assert device.fault is not None and device.fault.kind == "collision"
    assert "stand" in str(device.fault)
    # The stand's face is 130 cm ahead of the centre, the body's front 40 cm.
    assert device.fault.pose.x == pytest.approx(200 + 130 - 40, abs=1.1)


def test_hitting_a_wall_while_turning() -> None:
    wall = Block("wall", ((540.0, 400.0), (560.0, 400.0), (560.0, 600.0), (540.0, 600.0)))
    result, device = _run(replace(open_floor(), blocks=(wall,)), "(ROT 90)\n(END)\n")
    assert device.fault is not None and device.fault.kind == "collision"
    assert result.fault is not None and result.fault.line == 1


def test_the_time_limit_stops_a_run_that_waits_forever() -> None:
    world = replace(open_floor(), time_limit=5.0)
    result, device = _run(world, ":10 (TIM 10)\n#10\n")
    assert device.fault is not None and device.fault.kind == "time-limit"
    assert device.fault.time == pytest.approx(5.0, abs=1.0)
    assert result.fault is not None and result.fault.line == 1
