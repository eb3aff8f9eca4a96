"""The camera and image processor against closed forms: moments of known shapes, the
marker's centroid (Fig. 3), the floor seen from above; and the ultrasonic sensors."""

from __future__ import annotations

import math
from dataclasses import replace

import msgspec
import numpy as np
import pytest
from support.worlds import line_world, open_floor, stand_world

from rl1.vm.sim.camera import focal, moments
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.world import Block, Vehicle


def test_moments_of_a_rectangle() -> None:
    image = np.zeros((40, 60), dtype=bool)
    image[10:20, 5:45] = True  # 40 wide, 10 high
    found = moments(image, (100, 50))
    assert found.area == 400
    assert (found.x, found.y) == pytest.approx((100 + 25, 50 + 15))
    assert found.angle == pytest.approx(0)


def test_moments_of_a_diagonal_bar_give_its_angle() -> None:
    image = np.zeros((100, 100), dtype=bool)
    for i in range(80):
        image[10 + i, 10 + i] = True
    found = moments(image, (0, 0))
    assert found.area == 80
    assert found.angle == pytest.approx(45)  # y grows downward


def _marker_reading(distance: float) -> tuple[int, int, int]:
    device = SimDevice(stand_world(distance))
    device.camera_up()
    device.select_scene(2)
    reading = device.measure_image()
    return reading.area, reading.x, reading.y


@pytest.mark.parametrize("distance", [45.0, 60.0, 100.0, 200.0])
def test_the_marker_centroid_gives_the_distance(distance: float) -> None:
    area, x, y = _marker_reading(distance)
    f = focal(Vehicle())
    assert x == 128
    # Upper LED on the axis, lower 6 cm below: the centroid half way, 3 f / d below.
    assert y == pytest.approx(120 + 3 * f / distance, abs=1)
    assert area == pytest.approx(2 * math.pi * (f / distance) ** 2, rel=0.2)


def test_the_marker_centroid_moves_down_as_the_vehicle_approaches() -> None:
    ys = [_marker_reading(d)[2] for d in (200.0, 150.0, 100.0, 70.0, 45.0)]
    assert ys == sorted(ys)
    assert ys[0] < 160 < ys[-1]


def test_image_x_grows_to_the_left() -> None:
    device = SimDevice(stand_world(100))
    device.camera_up()
    device.select_scene(2)
    device.camera_pan_pulse(392 - 10)  # pan right: the marker appears left of centre
    reading = device.measure_image()
    f = focal(Vehicle())
    assert reading.x == pytest.approx(128 + f * math.tan(math.radians(10 * 180 / 784)), abs=1.5)


def test_a_marker_behind_its_face_is_not_seen() -> None:
    world = stand_world(100)
    device = SimDevice(replace(world, stands=(replace(world.stands[0], facing=0.0),)))
    device.camera_up()
    device.select_scene(2)
    assert device.measure_image().area == 0


def test_the_line_seen_from_above_runs_up_the_image() -> None:
    device = SimDevice(line_world())
    device.camera_down()
    reading = device.measure_image()
    assert reading.x == 128
    assert abs(reading.z) == 90  # the principal axis along the image's y
    assert reading.area > 0


def test_an_undefined_scene_sees_nothing() -> None:
    device = SimDevice(line_world())
    device.camera_down()
    device.select_scene(5)
    assert device.measure_image().area == 0


@pytest.mark.parametrize(("sensor", "dx", "dy"), [("A", 1, 0), ("B", 0, -1), ("C", -1, 0),
                                                  ("D", 0, 1)])
def test_ultrasonic_reads_the_nearest_wall_in_its_cone(sensor: str, dx: int, dy: int) -> None:
    gap = 70.0
    world = open_floor()
    half = 40.0 if dx else 30.0  # half length ahead and behind, half width aside
    near = 500 + (half + gap) * (dx + dy)
    far = near + 10 * (dx + dy)
    if dx:
        wall = ((near, 300.0), (far, 300.0), (far, 700.0), (near, 700.0))
    else:
        wall = ((300.0, near), (700.0, near), (700.0, far), (300.0, far))
    device = SimDevice(replace(world, blocks=(Block("wall", wall),)))
    assert device.ultrasonic(sensor) == pytest.approx(gap, abs=1)
    assert SimDevice(world).ultrasonic(sensor) == 100  # nothing within its reach


def test_a_sensor_delay_reports_where_the_vehicle_was() -> None:
    world = stand_world(150)
    delayed = replace(world, noise=msgspec.structs.replace(world.noise, delay=2.0))
    readings = []
    for each in (world, delayed):
        device = SimDevice(each)
        device.camera_up()
        device.select_scene(2)
        device.move(2, 2)  # 10 cm/s towards the marker
        device.wait(40)
        readings.append(device.measure_image().y)
    f = focal(Vehicle())
    # Driving from 0.2 s (after the tilt) to the image at 4.24 s: 40.4 cm nearer; the
    # delayed sensor sees the vehicle of 2.24 s, 20.4 cm nearer.
    assert readings[0] == pytest.approx(120 + 3 * f / (150 - 40.4), abs=0.5)
    assert readings[1] == pytest.approx(120 + 3 * f / (150 - 20.4), abs=0.5)
