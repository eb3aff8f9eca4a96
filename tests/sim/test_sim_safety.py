"""Safety stops: leaving the floor, hitting a stand or a wall, the time limit. Each stops
the vehicle first and says which, where and when; the engine adds the source line."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from support.cli import rl1c
from support.worlds import open_floor, stand_world

from rl1.compiler.runner import Finished, run
from rl1.vm.faults import FaultKind, RunResult
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.world import Block, World, decode_world


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


def test_a_collision_names_the_wall_or_obstacle_as_the_world_file_does() -> None:
    world = decode_world(b'[floor]\nsize = [1000, 1000]\n[start]\nx = 500\ny = 500\n'
                         b'[[walls]]\nname = "north"\npoints = [[0, 990], [1000, 990], '
                         b'[1000, 1000], [0, 1000]]\n'
                         b'[[walls]]\npoints = [[990, 0], [1000, 0], [1000, 990], [990, 990]]\n'
                         b'[[obstacles]]\npoints = [[100, 100], [200, 100], [200, 200], '
                         b'[100, 200]]\n',
                         "w.toml")
    assert [(b.kind, b.name) for b in world.blocks] == [
        ("wall", "north"), ("wall", "at (995, 495)"), ("obstacle", "at (150, 150)")]
    for text, hit in (("(ROT 90); (MOV 12,12); (TIM 100)\n", "the wall north"),
                      ("(MOV 12,12); (TIM 100)\n", "the wall at (995, 495)"),
                      ("(ROT -135); (MOV 12,12); (TIM 100); (TIM 100)\n",
                       "the obstacle at (150, 150)")):
        result, device = _run(world, text)
        assert device.fault is not None and device.fault.kind == "collision"
        assert f"the vehicle hit {hit} at " in str(device.fault)
        assert result.fault is not None and hit in result.fault.message


@pytest.mark.parametrize(("program", "kind"), [
    ("(MOV 12,12)\n(TIM 100)\n(END)\n", "collision"),
    ("(ROT 180); (MOV 12,12)\n(TIM 100)\n(END)\n", "off-floor"),
    (":10 (TIM 100)\n#10\n", "time-limit")])
def test_a_safety_stop_says_what_to_do_in_the_simulator_s_words(
        tmp_path: Path, program: str, kind: str) -> None:
    source, world = tmp_path / "p.rob", tmp_path / "w.toml"
    source.write_text(program)
    world.write_text('[floor]\nsize = [1000, 1000]\n[start]\nx = 500\ny = 500\n[limits]\n'
                     'time = 30\n[[walls]]\nname = "east"\n'
                     'points = [[900, 0], [910, 0], [910, 1000], [900, 1000]]\n')
    result = rl1c("sim", source, "--world", world, "--trace", "none")
    assert result.exit_code == 13, result.output
    assert f"safety stop [{kind}]" in result.stdout
    (help_line,) = [line for line in result.stdout.splitlines() if "= help:" in line]
    assert "--svg FILE" in help_line
    assert "scripted" not in help_line and "sensor script" not in help_line
