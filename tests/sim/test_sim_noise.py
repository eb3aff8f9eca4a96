"""The vehicle's imperfections (vm/sim/noise.py, spec/simulator.md "Noise"): exact when
off, seeded, within what each sensor can report, and drawn at the rates the world sets
(each rate measured over many seeded draws against a bound it misses with a chance far
below one in a million, so that a wrong rate fails and a right one never does)."""

from __future__ import annotations

import math
import statistics
from dataclasses import replace

import msgspec
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.worlds import line_world, open_floor, stand_world

from rl1.vm.sim.camera import Moments
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.motion import Pose
from rl1.vm.sim.noise import Imperfections
from rl1.vm.sim.tracing import LineView
from rl1.vm.sim.world import NOISELESS, Block, Noise, World, WorldError, decode_world

BOUND = 5.0  # standard errors: a right rate falls outside with a chance under 1e-6
TREAD = 50.0  # cm, the default
FLOOR = b'[floor]\nsize = [1000, 1000]\n\n[start]\nx = 500\ny = 500\n'


def only(**settings_: float) -> Noise:
    """No noise but the settings named."""
    return msgspec.structs.replace(NOISELESS, **settings_)


def noisy(world: World, noise: Noise) -> World:
    return replace(world, noise=noise)


def walled(distance: float) -> World:
    """The open floor with a wall `distance` cm ahead of the front sensor (the vehicle
    at (500, 500) facing +x, its front 40 cm ahead of its centre)."""
    x = 540.0 + distance
    return replace(open_floor(), blocks=(Block("wall", ((x, 0.0), (x + 10, 0.0),
                                                        (x + 10, 1000.0), (x, 1000.0))),))


def within_normal(values: list[float], mean: float, sd: float) -> None:
    """The sample's mean and standard deviation are those of a normal law (mean, sd)."""
    n = len(values)
    assert abs(statistics.fmean(values) - mean) <= BOUND * sd / math.sqrt(n)
    assert abs(statistics.stdev(values) / sd - 1) <= BOUND / math.sqrt(2 * (n - 1))


# Off: exactly today's runs -----------------------------------------------------------

finite = st.floats(-1e4, 1e4, allow_nan=False)


@settings(max_examples=300)
@given(seed=st.integers(0, 2**32 - 1), x=finite, y=finite, heading=finite, left=finite,
       right=finite, seconds=st.floats(0, 10), distance=st.floats(0, 2000),
       reach=st.floats(1, 1000), area=st.integers(0, 60000), angle=st.floats(-90, 90))
def test_without_noise_every_value_passes_through_exactly(
        seed: int, x: float, y: float, heading: float, left: float, right: float,
        seconds: float, distance: float, reach: float, area: int, angle: float) -> None:
    model = Imperfections(NOISELESS, seed)
    pose = Pose(x, y, heading)
    assert model.start(pose) == pose
    assert model.wheels(left, right) == (left, right)
    assert model.ground(left, right, seconds) == (left, right)
    assert model.steering == 0.0
    assert model.ultrasonic(distance, reach) == min(distance, reach)
    found = Moments(area, x, y, angle)
    assert model.image(found, (0, 0, 256, 240)) == found
    view = LineView(x, heading)
    assert model.line(view) == view


def test_noise_is_off_unless_the_world_turns_it_on() -> None:
    assert decode_world(FLOOR, "w.toml").noise == NOISELESS
    assert decode_world(b"noise = false\n" + FLOOR, "w.toml").noise == NOISELESS
    zeros = "".join(f"{key} = 0\n" for key in Noise.__struct_fields__)
    assert decode_world(FLOOR + b"\n[noise]\n" + zeros.encode(), "w.toml").noise == NOISELESS
    assert decode_world(b"noise = true\n" + FLOOR, "w.toml").noise == Noise()
    # A table sets what it names; the rest keep their defaults.
    table = decode_world(FLOOR + b"\n[noise]\nslip = 2\n", "w.toml").noise
    assert table == msgspec.structs.replace(Noise(), slip=2.0)
    assert all(getattr(Noise(), key) > 0 for key in Noise.__struct_fields__ if key != "delay")


@pytest.mark.parametrize(("text", "says"), [
    (b"noise = 3\n", "w.toml:1: noise: expected a table or true or false, found 3"),
    (FLOOR + b"\n[noise]\nslip = 50\n", "w.toml:9: noise.slip: 50 is outside 0..10"),
    (FLOOR + b"\n[noise]\nsilp = 1\n",
     "w.toml:9: noise.silp: unknown key; did you mean slip? (expected one of "),
])
def test_a_bad_noise_setting_says_where_and_what(text: bytes, says: str) -> None:
    with pytest.raises(WorldError) as refused:
        decode_world(text if text.startswith(b"[") else text + FLOOR, "w.toml")
    assert str(refused.value).startswith(says)


def _errand(device: SimDevice) -> list[object]:
    """A little of everything the noise touches: the start, motion, steering, tracing,
    the odometer, the camera and the ultrasonic sensors; what the device reported."""
    device.camera_down()
    device.set_tracing(1)
    device.move(4, 4)
    device.wait(30)
    device.steer_left(20)
    device.move_distance(3, 5, 60)
    device.rotate(-45)
    return [device.read_distance(), device.measure_image(), device.ultrasonic("A"),
            device.sim.pose, device.trace[-1]]


def test_without_noise_the_seed_changes_nothing() -> None:
    world = line_world(offset=3.0, angle=4.0)
    assert _errand(SimDevice(world, seed=0)) == _errand(SimDevice(world, seed=12345))


# Seeded: the same seed, the same run --------------------------------------------------


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_same_seed_gives_the_same_run(seed: int) -> None:
    world = noisy(line_world(offset=3.0, angle=4.0), Noise())
    assert _errand(SimDevice(world, seed=seed)) == _errand(SimDevice(world, seed=seed))


def test_a_setting_turned_on_leaves_the_other_draws_alone() -> None:
    alone = Imperfections(only(odometry=0.01), 13)
    joined = Imperfections(only(odometry=0.01, wheel_speed=0.02, steering_deg=1.0), 13)
    assert joined.scale == alone.scale
    assert joined.speed != (1.0, 1.0) and joined.steering != 0.0


def test_other_seeds_give_other_runs() -> None:
    world = noisy(line_world(offset=3.0, angle=4.0), Noise())
    poses = {_errand(SimDevice(world, seed=seed))[3] for seed in range(5)}
    assert len(poses) == 5


def test_a_sensor_read_more_often_leaves_the_others_draws_alone() -> None:
    world = noisy(replace(stand_world(100.0), blocks=walled(50.0).blocks), Noise())
    quiet, busy = SimDevice(world, seed=3), SimDevice(world, seed=3)
    quiet.wait(1)
    for _ in range(5):  # as long as the wait
        busy.ultrasonic("A")
    assert [quiet.measure_image() for _ in range(3)] == [busy.measure_image()
                                                         for _ in range(3)]
    assert quiet.sim.pose == busy.sim.pose


# Odometry: drifts with the wheels, never while standing ----------------------------------


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_a_standing_vehicle_s_odometry_never_changes(seed: int) -> None:
    device = SimDevice(noisy(walled(80.0), Noise()), seed=seed)
    device.move_distance(5, 4, 50)
    first = device.read_distance()
    readings = []
    for _ in range(20):
        device.wait(5)
        device.measure_image()
        device.ultrasonic("A")
        device.camera_pan_angle(45)
        device.steer_right(10)
        readings.append(device.read_distance())
    assert readings == [first] * 20
    assert first.centre != 0


@pytest.mark.parametrize("cm", [100, 400])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_straight_run_s_odometry_error_is_its_wheels_scale_error(cm: int, seed: int) -> None:
    """The counters read `cm`; on the floor each wheel went `cm` times its scale, so
    the centre went along an arc of length cm x the mean scale, turning by
    cm (right - left) / tread: the error grows in proportion to the distance."""
    noise = only(odometry=0.01)
    device = SimDevice(noisy(open_floor(), noise), seed=seed)
    device.move_distance(4, 4, cm)
    left, right = Imperfections(noise, seed).scale  # the run's, by its seed
    assert device.read_distance().centre == cm
    length = cm * (left + right) / 2
    turn = cm * (right - left) / TREAD
    chord = length * math.sin(turn / 2) / (turn / 2)
    pose = device.sim.pose
    assert math.hypot(pose.x - 500, pose.y - 500) == pytest.approx(chord, abs=1e-6)
    assert pose.heading == pytest.approx(turn, abs=1e-9)
    assert math.atan2(pose.y - 500, pose.x - 500) == pytest.approx(turn / 2, abs=1e-9)


def test_the_wheels_scale_errors_are_drawn_at_their_setting() -> None:
    scales = [scale - 1 for seed in range(2000)
              for scale in Imperfections(only(odometry=0.01), seed).scale]
    within_normal(scales, 0.0, 0.01)


@pytest.mark.parametrize("step", [0.05, 0.01])
@pytest.mark.parametrize("cm", [100, 400])
def test_slip_grows_with_the_square_root_of_the_distance(cm: int, step: float) -> None:
    """Each wheel slips by a random walk of `slip` cm per metre it turns, whatever the
    steps its travel is cut into: over `cm` it errs by slip x sqrt(cm / 100)."""
    model = Imperfections(only(slip=2.0), 12)
    errors: list[float] = []
    for _ in range(1000):
        travelled = [0.0, 0.0]
        for _ in range(round(cm / 30 / step)):  # at 30 cm/s
            left, right = model.ground(30.0, 30.0, step)
            travelled[0] += left * step
            travelled[1] += right * step
        errors += [travel - 30.0 * step * round(cm / 30 / step) for travel in travelled]
    within_normal(errors, 0.0, 2.0 * math.sqrt(cm / 100))


def test_a_motor_s_speed_error_shows_in_its_counter() -> None:
    noise = only(wheel_speed=0.05)
    device = SimDevice(noisy(open_floor(), noise), seed=4)
    device.move(4, 4)
    device.wait(50)  # 5 s at 20 cm/s
    left, right = Imperfections(noise, 4).speed
    reading = device.read_distance()
    assert (reading.left, reading.right) == (round(100 * left), round(100 * right))
    assert (left, right) != (1.0, 1.0)


def test_the_steering_offset_turns_the_direction_of_travel() -> None:
    noise = only(steering_deg=2.0)
    device = SimDevice(noisy(open_floor(), noise), seed=5)
    device.move_distance(4, 4, 200)
    offset = Imperfections(noise, 5).steering
    assert offset != 0.0
    pose = device.sim.pose
    assert (pose.x, pose.y) == pytest.approx((500 + 200 * math.cos(offset),
                                              500 + 200 * math.sin(offset)), abs=1e-6)


def test_the_start_is_uncertain_by_its_setting() -> None:
    starts = [SimDevice(noisy(open_floor(), only(start_cm=2.0, start_deg=1.5)), seed=seed)
              .sim.pose for seed in range(1000)]
    within_normal([pose.x for pose in starts], 500.0, 2.0)
    within_normal([pose.y for pose in starts], 500.0, 2.0)
    within_normal([math.degrees(pose.heading) for pose in starts], 0.0, 1.5)


# Ultrasonic: no echo beyond its reach, within what it can report, dropouts -----------------


@settings(max_examples=300)
@given(seed=st.integers(0, 2**32 - 1), distance=st.floats(0, 2000),
       reach=st.floats(1, 1000), sd=st.floats(0, 100), blind=st.floats(0, 100),
       dropout=st.floats(0, 1))
def test_an_ultrasonic_reading_stays_within_what_the_sensor_reports(
        seed: int, distance: float, reach: float, sd: float, blind: float,
        dropout: float) -> None:
    model = Imperfections(only(ultrasonic_cm=sd, ultrasonic_blind=blind,
                               ultrasonic_dropout=dropout), seed)
    for _ in range(5):
        reading = model.ultrasonic(min(distance, reach), reach)
        assert min(blind, reach) <= reading <= reach
        if distance >= reach:
            assert reading == reach  # nothing in range: no echo, no noise


def test_nothing_in_range_reads_the_range_exactly() -> None:
    device = SimDevice(noisy(open_floor(), Noise(ultrasonic_cm=25.0)), seed=6)
    assert {device.ultrasonic(sensor) for sensor in "ABCD" for _ in range(50)} == {100}


def test_near_a_wall_the_reading_is_clipped_to_the_blind_zone() -> None:
    device = SimDevice(noisy(walled(2.0), only(ultrasonic_cm=5.0, ultrasonic_blind=8.0)),
                       seed=7)
    readings = [device.ultrasonic("A") for _ in range(200)]
    assert min(readings) == 8  # never below what the sensor can report (not -1)
    assert max(readings) < 100


def test_ultrasonic_noise_and_dropouts_come_at_their_rates() -> None:
    model = Imperfections(only(ultrasonic_cm=3.0, ultrasonic_dropout=0.1), 8)
    draws = 20000
    readings = [model.ultrasonic(50.0, 100.0) for _ in range(draws)]
    dropped = readings.count(100.0)
    assert abs(dropped - 0.1 * draws) <= BOUND * math.sqrt(draws * 0.1 * 0.9)
    within_normal([reading for reading in readings if reading != 100.0], 50.0, 3.0)


# The camera and the tracing ------------------------------------------------------------


def test_image_noise_comes_at_its_rates_on_area_centroid_and_angle() -> None:
    model = Imperfections(only(image_px=0.5, image_area=0.05, image_deg=2.0), 9)
    found = Moments(4000, 120.0, 100.0, 10.0)
    seen = [model.image(found, (0, 0, 256, 240)) for _ in range(5000)]
    within_normal([m.x for m in seen], 120.0, 0.5)
    within_normal([m.y for m in seen], 100.0, 0.5)
    within_normal([m.angle for m in seen], 10.0, 2.0)
    # The area is whole pixels: its rounding adds a uniform error of variance 1/12.
    within_normal([m.area for m in seen], 4000.0, math.hypot(200.0, math.sqrt(1 / 12)))


def test_image_noise_keeps_to_the_window_and_never_hides_or_invents_a_feature() -> None:
    model = Imperfections(only(image_px=5.0, image_area=1.0, image_deg=60.0), 10)
    window = (98, 117, 158, 123)
    for _ in range(2000):
        seen = model.image(Moments(3, 98.6, 122.4, 89.0), window)
        assert 1 <= seen.area <= 60 * 6
        assert 98.5 <= seen.x <= 157.5 and 117.5 <= seen.y <= 122.5
        assert -90 < seen.angle <= 90
    assert model.image(Moments(0, 0.0, 0.0, 0.0), window) == Moments(0, 0.0, 0.0, 0.0)


def test_the_traced_line_is_measured_with_its_noise() -> None:
    model = Imperfections(only(line_cm=0.4, line_deg=3.0), 11)
    views = [model.line(LineView(1.5, 0.2)) for _ in range(5000)]
    assert all(view is not None for view in views)
    within_normal([view.offset for view in views if view], 1.5, 0.4)
    within_normal([view.angle for view in views if view], 0.2, math.radians(3.0))
    assert model.line(None) is None  # a line out of view stays out of view


def test_a_vehicle_traces_its_line_through_the_default_noise() -> None:
    """Tracing corrects what the noise disturbs: after 4 m the vehicle is still on the
    line, as the paper's vehicle was."""
    for seed in range(5):
        device = SimDevice(noisy(line_world(offset=3.0, angle=4.0), Noise()), seed=seed)
        device.camera_down()
        device.set_tracing(1)
        device.move_distance(6, 6, 400)
        assert abs(device.sim.pose.y - 500) < 2.0
