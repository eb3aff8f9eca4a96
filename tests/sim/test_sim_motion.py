"""Motion against closed forms: straight runs, turns in place, diagonal travel,
odometry, and poses that do not depend on the simulator's step."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.worlds import open_floor

from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.motion import Pose, advance

UNIT = 5.0  # cm/s per wheel speed unit, the default


@pytest.mark.parametrize(("speed", "cm"), [(3, 50), (12, 300), (-4, 120), (1, 7)])
def test_mvi_runs_straight_for_its_distance(speed: int, cm: int) -> None:
    device = SimDevice(open_floor())
    device.move_distance(speed, speed, cm)
    pose = device.sim.pose
    assert pose.x == pytest.approx(500 + math.copysign(cm, speed), abs=1e-6)
    assert pose.y == pytest.approx(500, abs=1e-9)
    assert device.sim.time == pytest.approx(cm / (abs(speed) * UNIT))
    assert device.sim.motion is None  # stopped afterwards


def test_mov_runs_on_through_a_wait_and_stops_on_mov_0_0() -> None:
    device = SimDevice(open_floor())
    device.move(2, 2)
    device.wait(30)  # 3 s at 10 cm/s
    device.move(0, 0)
    device.wait(10)
    assert device.sim.pose.x == pytest.approx(530)


@pytest.mark.parametrize("degrees", [90, -90, 180, 45, -360])
def test_rot_turns_in_place(degrees: int) -> None:
    device = SimDevice(open_floor())
    device.rotate(degrees)
    pose = device.sim.pose
    assert (pose.x, pose.y) == pytest.approx((500, 500), abs=1e-6)
    assert pose.heading == pytest.approx(math.radians(degrees))
    # Each wheel travels the arc of its half tread, opposite ways; the centre nothing.
    centre, right, left = device.sim.distance()
    assert right == pytest.approx(math.radians(degrees) * 25)
    assert left == pytest.approx(-right)
    assert centre == pytest.approx(0, abs=1e-9)


@pytest.mark.parametrize("tenths", [450, -450, 900, 300])
def test_steered_drive_unit_travels_diagonally_without_turning(tenths: int) -> None:
    device = SimDevice(open_floor())
    device.steer_by(tenths)
    device.move_distance(2, 2, 100)
    pose = device.sim.pose
    angle = math.radians(tenths / 10)
    assert (pose.x, pose.y) == pytest.approx((500 + 100 * math.cos(angle),
                                              500 + 100 * math.sin(angle)))
    assert pose.heading == pytest.approx(0)


def test_str_and_stl_are_relative_and_org_returns() -> None:
    device = SimDevice(open_floor())
    device.steer_left(75)
    device.steer_right(30)
    assert math.degrees(device.sim.steering) == pytest.approx(45)
    device.steering_origin()
    assert device.sim.steering == 0


def test_unequal_wheels_drive_the_closed_form_arc() -> None:
    pose = advance(Pose(0, 0, 0), 0.0, 10.0, 20.0, 50.0, 5.0)
    turn, speed = 10 / 50, 15.0
    radius = speed / turn
    assert pose.heading == pytest.approx(turn * 5)
    assert pose.x == pytest.approx(radius * math.sin(turn * 5))
    assert pose.y == pytest.approx(radius * (1 - math.cos(turn * 5)))


def test_kyo_reads_centre_right_left_and_kyc_clears() -> None:
    device = SimDevice(open_floor())
    device.move_distance(2, 4, 90)  # centre 90 cm; right wheel twice the left's travel
    reading = device.read_distance()
    assert (reading.centre, reading.right, reading.left) == (90, 120, 60)
    device.clear_distance()
    assert device.read_distance().centre == 0


def test_mvi_whose_wheels_cancel_is_refused() -> None:
    from rl1.vm.device import DeviceError
    with pytest.raises(DeviceError, match="would never end"):
        SimDevice(open_floor()).move_distance(3, -3, 10)


program = st.lists(st.one_of(
    st.tuples(st.just("mov"), st.integers(-12, 12), st.integers(-12, 12)),
    st.tuples(st.just("mvi"), st.integers(1, 12), st.integers(-12, 12),
              st.integers(1, 60)).filter(lambda c: c[1] + c[2] != 0),
    st.tuples(st.just("tim"), st.integers(1, 30)),
    st.tuples(st.just("stx"), st.integers(-1800, 1800)),
    st.tuples(st.just("rot"), st.integers(-360, 360)),
), max_size=8)


def _drive(step: float, commands: list[tuple[object, ...]]) -> SimDevice:
    big = replace(open_floor(), floor=(1e5, 1e5), start=(5e4, 5e4, 0.0))
    device = SimDevice(big, step=step)
    for command in commands:
        name, *args = command
        values = [int(a) for a in args]  # type: ignore[call-overload]
        if name == "mov":
            device.move(values[0], values[1])
        elif name == "mvi":
            device.move_distance(values[0], values[1], values[2])
        elif name == "tim":
            device.wait(values[0])
        elif name == "stx":
            device.steer_by(values[0])
        else:
            device.rotate(values[0])
    return device


@settings(max_examples=60, deadline=None)
@given(program)
def test_halving_the_step_moves_the_final_pose_by_less_than_a_centimetre(
        commands: list[tuple[object, ...]]) -> None:
    coarse, fine = _drive(0.05, commands), _drive(0.025, commands)
    a, b = coarse.sim.pose, fine.sim.pose
    assert math.hypot(a.x - b.x, a.y - b.y) < 1.0
    assert abs(a.heading - b.heading) < math.radians(0.5)


@settings(max_examples=60, deadline=None)
@given(program)
def test_odometry_agrees_with_the_wheels(commands: list[tuple[object, ...]]) -> None:
    device = _drive(0.05, commands)
    times = [time for time, _ in device.sim.track]
    assert times == sorted(times)  # the clock never runs back
    centre, right, left = device.sim.distance()
    assert centre == pytest.approx((right + left) / 2, abs=1e-6)
    # The heading changes by the wheels' difference over the tread, whatever the path.
    assert device.sim.pose.heading == pytest.approx((right - left) / 50, abs=1e-6)
