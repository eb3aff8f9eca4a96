"""Line tracing: the paper's law brings the vehicle onto the line, and Table 4 decides
what a lost line does."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support.worlds import line_world, round_track

from rl1.vm.device import LineLost
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.geometry import segment_nearest
from rl1.vm.sim.tracing import LineIndex, LineView, correct
from rl1.vm.sim.world import Line


def _tracing(offset: float, angle: float, mode: int = 3, end: float = 1000.0) -> SimDevice:
    world = line_world(offset, angle)
    device = SimDevice(replace(world, lines=(replace(world.lines[0], points=(
        (0.0, 500.0), (end, 500.0))),)))
    device.camera_pan_angle(90)
    device.camera_down()
    device.set_tracing(mode)
    device.move(3, 3)
    return device


@pytest.mark.parametrize(("offset", "angle"), [(8, 0), (-8, 0), (0, 5), (0, -5), (4, -6)])
def test_tracing_converges_onto_the_line(offset: float, angle: float) -> None:
    device = _tracing(offset, angle)
    device.wait(100)
    device.wait(100)  # 20 s at 15 cm/s: 3 m
    pose = device.sim.pose
    assert abs(pose.y - 500) < 0.5
    assert abs(math.degrees(pose.heading)) < 0.5
    assert device.pending is None
    assert pose.x > 100 + 280  # it kept going along the line


def test_without_tracing_the_offset_stays() -> None:
    device = _tracing(8, 0, mode=0)
    device.wait(100)
    assert device.sim.pose.y == pytest.approx(508)


def test_the_law_turns_towards_the_line() -> None:
    # A line to the right and turning right: the left wheel speeds up, the right slows.
    left, right = correct(3, 3, LineView(offset=5.0, angle=0.1), k1=0.02, k2=0.3)
    v_d = 3 * (0.02 * 5.0 + 0.3 * math.tan(0.1))
    assert (left, right) == pytest.approx((3 + v_d, 3 - v_d))


@pytest.mark.parametrize(("mode", "handler_hears", "keeps_moving"),
                         [(1, False, True), (2, True, False), (3, True, True)])
def test_a_lost_line_follows_table_4(mode: int, handler_hears: bool, keeps_moving: bool) -> None:
    device = _tracing(0, 0, mode, end=500.0)  # drive off the line's end
    device.move(12, 12)
    device.wait(100)
    lost = [e for e in device.sim.events if e.kind == "lost"]
    assert len(lost) == 1
    # Lost when the line's end (and its half width) leaves the view's half width:
    # the view centre is 30 + 40/tan(50 deg) cm ahead of the vehicle's centre.
    view_ahead = 30 + 40 / math.tan(math.radians(50))
    half_width = 40 / math.sin(math.radians(50)) * math.tan(math.radians(11))
    assert lost[0].pose.x == pytest.approx(500 + 1 + half_width - view_ahead, abs=3.1)
    assert (device.poll_event() is not None) == handler_hears
    assert (device.sim.motion is not None) == keeps_moving


def test_after_the_end_a_tracing_vehicle_runs_on_until_mode_2_stops_it() -> None:
    device = _tracing(0, 0, mode=2, end=500.0)
    run_on = device.run_on()  # as after (END) with (MOV 3,3) in effect
    assert run_on is not None and run_on.stop is None
    view_ahead = 30 + 40 / math.tan(math.radians(50))
    half_width = 40 / math.sin(math.radians(50)) * math.tan(math.radians(11))
    assert device.sim.pose.x == pytest.approx(500 + 1 + half_width - view_ahead, abs=1)
    assert run_on.seconds == pytest.approx((device.sim.pose.x - 100) / 15)
    assert device.run_on() is None  # standing now


def test_a_lost_line_during_mvi_interrupts_it_in_mode_2() -> None:
    device = _tracing(0, 0, mode=2, end=500.0)
    device.move(0, 0)
    device.move_distance(12, 12, 600)  # would go past the line's end
    assert device.poll_event() == LineLost("MVI", 2)
    assert device.sim.motion is None
    assert device.sim.pose.x < 500


def test_a_program_hears_of_a_lost_line_at_its_handler() -> None:
    from rl1.compiler.runner import Finished, run

    world = line_world()
    world = replace(world, lines=(replace(world.lines[0], points=((0.0, 500.0),
                                                                   (400.0, 500.0))),))
    device = SimDevice(world)
    text = "(CAM D); (TRC 3); (MOV 6,6)\n:10 (TIM 1); #10\n:96 (MOV 0,0); H=1; (END)\n"
    finished = run(text, device)
    assert isinstance(finished, Finished) and finished.result.fault is None
    assert finished.result.named()["H"] == 1
    kinds = [event.kind for event in device.sim.events]
    assert kinds == ["lost", "handler"]
    assert "jump to :96" in device.sim.events[1].text


def test_halving_the_step_leaves_a_patrol_where_it_was() -> None:
    from rl1.compiler.runner import Finished, run

    patrol = ("(CAM A 90); (CAM D); (SCN 0); (TRC 1); (KYC)\nN=60\n"
              ":10 (MOV 4,4); (TIM 10); A=(ULT A); B=(KYO); C=(IMG); N--\n?N>#10\n"
              "(MOV 0,0); (FRE); (END)\n")
    ends = []
    for step in (0.05, 0.025):
        device = SimDevice(round_track(), step=step)
        finished = run(patrol, device)
        assert isinstance(finished, Finished) and finished.result.fault is None
        ends.append(device.sim.pose)
    # A minute at 20 cm/s, tracing all the way: nearly a lap of the 12.6 m track.
    assert device.sim.time > 60
    assert math.hypot(ends[0].x - ends[1].x, ends[0].y - ends[1].y) < 1.0
    assert abs(ends[0].heading - ends[1].heading) < math.radians(0.5)


_coordinates = st.floats(-2000, 2000)
_points = st.tuples(_coordinates, _coordinates)


@given(lines=st.lists(st.lists(_points, min_size=2, max_size=5), min_size=1, max_size=4),
       x=_coordinates, y=_coordinates, reach=st.floats(0, 1e6))
def test_the_line_index_finds_every_piece_within_reach(
        lines: list[list[tuple[float, float]]], x: float, y: float, reach: float) -> None:
    """Whatever the reach, a few centimetres or more than the floor (a line 10 km wide
    makes one), and whichever way near() looks, it misses no piece that comes so near."""
    index = LineIndex([Line(f"line {n}", tuple(points), 2.0) for n, points in enumerate(lines)])
    within = {number for number, piece in enumerate(index.pieces)
              if segment_nearest(x, y, piece.a, piece.b)[2] <= reach}
    assert within <= index.near(x, y, reach)
