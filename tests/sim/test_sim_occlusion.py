"""What stands between the camera and what it looks at hides it (spec/simulator.md,
"Camera and image processor"): walls, obstacles and stands as high as the world file
says, against closed forms, on worlds written here rather than taken from examples/."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import msgspec.inspect as mi
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from support.worlds import line_world, stand_world

from rl1.vm.sim.camera import Moments, Scenery, View, focal, moments, view_of
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.geometry import Mask, Point, inside, rectangle, segment_nearest
from rl1.vm.sim.occlusion import hidden
from rl1.vm.sim.world import (
    LED_RADIUS,
    LED_SPACING,
    OBSTACLE_HEIGHT,
    STAND_HEIGHT,
    WALL_HEIGHT,
    Block,
    ObstacleTable,
    Stand,
    StandTable,
    Vehicle,
    WallTable,
    World,
    WorldError,
    decode_world,
)

VEHICLE = Vehicle()
F = focal(VEHICLE)
TILT = math.radians(VEHICLE.tilt_down)
# Where the camera is along +x, which stand_world's and line_world's vehicles face.
CAMERA_X = stand_world(100.0).start[0] + VEHICLE.camera_ahead
LINE_CAMERA_X = line_world().start[0] + VEHICLE.camera_ahead


def box(x0: float, y0: float, x1: float, y1: float) -> tuple[Point, ...]:
    return (x0, y0), (x1, y0), (x1, y1), (x0, y1)


def marker_image(world: World) -> tuple[Mask, Moments]:
    """The whole image of scene 2 (the markers) from stand_world's start, level."""
    x, y, heading = world.start
    view = view_of(x, y, math.radians(heading), 392, 0.0, world.vehicle)
    return _whole(world, 2, view)


def floor_image(world: World) -> tuple[Mask, Moments]:
    """The whole image of scene 0 (lines and marks) from line_world's start, tilted down."""
    x, y, heading = world.start
    view = view_of(x, y, math.radians(heading), 392, TILT, world.vehicle)
    return _whole(world, 0, view)


def _whole(world: World, scene: int, view: View) -> tuple[Mask, Moments]:
    """The image of `scene` in the whole image's frame, and its moments."""
    image, (left, top) = Scenery(world, world.scenes[scene]).render(view)
    whole = np.zeros((VEHICLE.image_height, VEHICLE.image_width), dtype=bool)
    whole[top:top + image.shape[0], left:left + image.shape[1]] = image
    return whole, moments(image, (left, top))


def with_wall(world: World, points: tuple[Point, ...], height: float) -> World:
    return replace(world, blocks=(Block("wall", points, height),))


def across_sight(distance: float, thickness: float = 2.0) -> tuple[Point, ...]:
    """A wall across the line of sight half way from the camera to a marker `distance`
    cm ahead, 2 m wide."""
    middle = CAMERA_X + distance / 2
    return box(middle - thickness / 2, 400.0, middle + thickness / 2, 600.0)


# The marker behind a wall -----------------------------------------------------------


@pytest.mark.parametrize("distance", [60.0, 150.0, 300.0])
def test_a_wall_taller_than_the_sightline_hides_the_marker(distance: float) -> None:
    world = stand_world(distance)
    assert marker_image(world)[1].area > 0
    hidden = with_wall(world, across_sight(distance), VEHICLE.camera_height + LED_RADIUS + 0.5)
    assert marker_image(hidden)[1].area == 0


@pytest.mark.parametrize("distance", [60.0, 150.0, 300.0])
def test_a_wall_under_the_sightline_changes_nothing(distance: float) -> None:
    world = stand_world(distance)
    # The lowest ray, to the bottom of the lower LED, is highest over the wall's far
    # face, 1 cm past half way: a wall just under it at its near face hides nothing.
    lowest = VEHICLE.camera_height - (LED_SPACING + LED_RADIUS) * (distance / 2 + 1) / distance
    image, found = marker_image(with_wall(world, across_sight(distance), lowest - 0.1))
    expected_image, expected = marker_image(world)
    assert found == expected
    assert (image == expected_image).all()


def test_a_wall_covering_the_right_half_of_the_marker_leaves_the_left_half() -> None:
    distance = 100.0
    world = stand_world(distance)
    # The vehicle faces +x, so its right is -y: the wall ends on the line of sight.
    half = with_wall(world, box(CAMERA_X + 40, 400.0, CAMERA_X + 42, 500.0), WALL_HEIGHT)
    _, whole = marker_image(world)
    image, found = marker_image(half)
    assert 2 * found.area == whole.area  # the image is symmetric about column 128
    assert not image[:, :128].any()  # x grows to the left: what is left is x >= 128
    # Each LED's image is nearly a disc of radius R = f r / d: its half's centroid is
    # 4 R / (3 pi) from the cut.
    radius = F * LED_RADIUS / distance
    assert whole.x == pytest.approx(128)
    assert found.x == pytest.approx(128 + 4 * radius / (3 * math.pi), abs=0.25)
    assert found.y == pytest.approx(whole.y)


def test_a_low_wall_hides_the_lower_led_and_the_centroid_rises_to_the_upper() -> None:
    distance = 150.0
    world = stand_world(distance)
    # Half way, the rays to the lower LED (34 +- 1 cm) pass under 37.5 cm, those to
    # the upper (40 +- 1 cm) over 39.4 cm.
    low = with_wall(world, across_sight(distance), 38.5)
    _, whole = marker_image(world)
    _, found = marker_image(low)
    assert found.area == pytest.approx(whole.area / 2, rel=0.05)
    assert whole.y == pytest.approx(120 + 3 * F / distance, abs=0.5)
    assert found.y == pytest.approx(120)  # the upper LED is level with the camera
    assert found.x == pytest.approx(128)


def test_a_stand_hides_the_marker_of_a_stand_behind_it_but_never_its_own() -> None:
    world = stand_world(200.0)
    (far,) = world.stands
    near = Stand("near", CAMERA_X + 60.0, 500.0, 40.0, 20.0, 180.0)  # face 50 cm ahead
    both = replace(world, stands=(far, near))
    _, found = marker_image(both)
    # Only the near marker is seen, 50 cm ahead: its centroid 3 f / 50 below the centre.
    assert found.y == pytest.approx(120 + 3 * F / 50, abs=0.5)
    _, alone = marker_image(replace(world, stands=(near,)))
    assert found == alone
    # A low stand with its marker on a post: the far marker is seen over it, and its
    # own above the far one in the image.
    low = replace(near, height=VEHICLE.camera_height - LED_SPACING - 2 * LED_RADIUS - 3,
                  marker_height=VEHICLE.camera_height + 8)
    _, over = marker_image(replace(world, stands=(far, low)))
    _, far_alone = marker_image(world)
    _, low_alone = marker_image(replace(world, stands=(low,)))
    assert over.area == far_alone.area + low_alone.area  # both seen, apart in the image


def test_a_marker_high_on_its_stand_appears_above_the_centre() -> None:
    distance, above = 100.0, 12.0
    world = stand_world(distance)
    (stand,) = world.stands
    raised = replace(world, stands=(replace(stand, marker_height=VEHICLE.camera_height
                                            + above),))
    _, found = marker_image(raised)
    # The upper LED `above` cm over the axis, the lower 6 cm under that: half way.
    assert found.y == pytest.approx(120 - (above - LED_SPACING / 2) * F / distance, abs=0.5)


# The floor behind a kerb -------------------------------------------------------------


def test_a_kerb_across_the_view_hides_the_near_floor_up_to_where_its_shadow_ends() -> None:
    world = line_world()
    height, near_face, far_face = 20.0, 15.0, 17.0  # cm, and ahead of the camera
    kerb = with_wall(world, box(LINE_CAMERA_X + near_face, 400.0, LINE_CAMERA_X + far_face,
                                600.0), height)
    whole, _ = floor_image(world)
    image, _ = floor_image(kerb)
    # A floor point D ahead is hidden when the ray to it passes under the kerb's top at
    # its far face: 40 (1 - 17 / D) < 20, D < 34 cm; the row seeing D = 34 is
    # f tan(atan(40 / 34) - tilt) from the centre.
    shadow = far_face * VEHICLE.camera_height / (VEHICLE.camera_height - height)
    boundary = 120 + F * math.tan(math.atan(VEHICLE.camera_height / shadow) - TILT)
    rows = np.arange(240) + 0.5
    assert whole[rows > boundary].any()
    assert not image[rows > boundary].any()
    assert (image[rows < boundary] == whole[rows < boundary]).all()


def test_the_floor_under_a_flat_obstacle_is_hidden() -> None:
    world = line_world()
    plate = with_wall(world, box(LINE_CAMERA_X + 30, 490.0, LINE_CAMERA_X + 37, 510.0), 1.0)
    whole, _ = floor_image(world)
    image, _ = floor_image(plate)
    assert image.sum() < whole.sum()
    # Beyond the plate's shadow (1 cm high, at 37 cm: to 37 x 40 / 39) all is seen.
    beyond = 37 * 40 / 39
    rows = np.arange(240) + 0.5
    far = rows < 120 + F * math.tan(math.atan(40 / beyond) - TILT) - 0.5
    assert (image[far] == whole[far]).all()


# Properties ----------------------------------------------------------------------------

walls = st.builds(
    lambda x, y, length, width, height: (box(x, y, x + length, y + width), height),
    st.floats(CAMERA_X - 100, CAMERA_X + 400), st.floats(300, 700), st.floats(0.5, 80),
    st.floats(0.5, 300), st.floats(1, 1000))


@settings(max_examples=150, deadline=None)
@given(distance=st.floats(45, 400), wall=walls)
def test_a_wall_only_ever_hides_the_marker(distance: float,
                                           wall: tuple[tuple[Point, ...], float]) -> None:
    world = stand_world(distance)
    image, found = marker_image(with_wall(world, *wall))
    whole, alone = marker_image(world)
    assert not (image & ~whole).any()
    points, height = wall
    beyond = min(x for x, _ in points) > CAMERA_X + distance + LED_RADIUS
    behind = max(x for x, _ in points) < CAMERA_X
    low = height < VEHICLE.camera_height - LED_SPACING - LED_RADIUS
    if beyond or behind or low:
        assert found == alone


@settings(max_examples=100, deadline=None)
@given(walls)
def test_a_wall_only_ever_hides_the_floor(wall: tuple[tuple[Point, ...], float]) -> None:
    world = line_world()
    image, _ = floor_image(with_wall(world, *wall))
    whole, _ = floor_image(world)
    assert not (image & ~whole).any()


@settings(max_examples=100, deadline=None)
@given(distance=st.floats(45, 400), part=st.floats(0.05, 0.95),
       over=st.floats(LED_RADIUS + 0.01, 500))
def test_a_wall_across_the_sight_taller_than_the_camera_hides_the_marker(
        distance: float, part: float, over: float) -> None:
    wall = box(CAMERA_X + part * distance - 1, 0.0, CAMERA_X + part * distance + 1, 1000.0)
    hidden = with_wall(stand_world(distance), wall, VEHICLE.camera_height + over)
    assert marker_image(hidden)[1].area == 0


def _clipped(target: Point, corners: list[Point]) -> tuple[float, float] | None:
    """The part s0..s1 of the segment from (0, 0) to `target` inside the convex polygon
    `corners` (counterclockwise), by clipping against each side's half-plane in turn
    (Cyrus-Beck); None when it misses."""
    low, high = 0.0, 1.0
    for i, (ax, ay) in enumerate(corners):
        bx, by = corners[(i + 1) % len(corners)]
        nx, ny = by - ay, ax - bx  # outward, the polygon on the left of each side
        towards, bound = nx * target[0] + ny * target[1], nx * ax + ny * ay
        if towards > 0:
            high = min(high, bound / towards)
        elif towards < 0:
            low = max(low, bound / towards)
        elif bound < 0:
            return None
    return (low, high) if low < high else None


@settings(max_examples=400, deadline=None)
@given(centre=st.tuples(st.floats(-300, 300), st.floats(-300, 300)),
       size=st.tuples(st.floats(1, 200), st.floats(1, 200)), turn=st.floats(0, 2 * math.pi),
       top=st.floats(1, 100), camera=st.floats(1, 100),
       target=st.tuples(st.floats(-400, 400), st.floats(-400, 400), st.floats(0, 100)))
def test_hidden_agrees_with_clipping_the_ray_by_the_prism(
        centre: Point, size: Point, turn: float, top: float, camera: float,
        target: tuple[float, float, float]) -> None:
    corners = rectangle(*centre, *size, turn)
    # The camera is never inside what it sees, nor on its side (a tie: a ray straight
    # down along the side is hidden or not as rounding decides).
    assume(not inside(0.0, 0.0, corners))
    sides = list(zip(corners, (*corners[1:], corners[0]), strict=True))
    assume(min(segment_nearest(0.0, 0.0, a, b)[2] for a, b in sides) > 1e-6)
    ahead, left, height = target
    part = _clipped((ahead, left), corners)
    lowest = None if part is None else min(camera + s * (height - camera) for s in part)
    # Away from the ties (a ray grazing a corner or the top, a target on a side), where
    # rounding decides.
    assume(min(segment_nearest(x, y, (0.0, 0.0), (ahead, left))[2] for x, y in corners) > 1e-6)
    assume(min(segment_nearest(ahead, left, a, b)[2] for a, b in sides) > 1e-6)
    assume(part is None or part[1] - part[0] > 1e-6)
    assume(lowest is None or abs(lowest - top) > 1e-6)
    found = hidden(np.array([ahead]), np.array([left]), np.array([height]), camera,
                   [(corners, top)])
    assert bool(found[0]) == (lowest is not None and lowest < top)


# The world file ---------------------------------------------------------------------------

WORLD = """
[floor]
size = [500, 300]

[start]
x = 100
y = 150

[[stands]]
name = "bench"
x = 330
y = 150
facing = 180
{stand}

[[walls]]
name = "screen"
points = [[240, 100], [242, 100], [242, 200], [240, 200]]
{wall}

[[scenes]]
number = 2
sees = ["markers"]
"""


def seen(stand: str = "", wall: str = "") -> tuple[int, int, int, int]:
    device = SimDevice(decode_world(WORLD.format(stand=stand, wall=wall).encode(), "w.toml"))
    device.camera_up()
    device.select_scene(2)
    reading = device.measure_image()
    return reading.area, reading.x, reading.y, reading.z


def test_a_world_file_s_wall_hides_the_stand_s_marker_behind_it() -> None:
    assert seen()[0] == 0  # 200 cm high by default
    assert seen(wall="height = 41.5")[0] == 0
    under = seen(wall="height = 35")  # the lowest ray passes its far face at 35.6 cm
    assert under[0] > 0
    camera_to_marker = 330 - 20 - (100 + VEHICLE.camera_ahead)
    assert under[2] == round(120 + 3 * F / camera_to_marker)
    raised = seen(stand="marker_height = 60", wall="height = 50")
    assert raised[2] < 120  # the LEDs over the camera's height, and over the wall


def test_heights_have_defaults_and_physical_ranges() -> None:
    def world(stand: str = "", wall: str = "") -> World:
        return decode_world(WORLD.format(stand=stand, wall=wall).encode(), "w.toml")

    loaded = world()
    assert (loaded.stands[0].height, loaded.stands[0].marker_height) == (STAND_HEIGHT, None)
    assert loaded.blocks[0].height == WALL_HEIGHT
    obstacle = decode_world(b"[floor]\nsize = [90, 90]\n[start]\nx = 1\ny = 1\n"
                            b"[[obstacles]]\npoints = [[5, 5], [6, 5], [6, 6]]\n", "w.toml")
    assert obstacle.blocks[0].height == OBSTACLE_HEIGHT
    assert world(stand="height = 1\nmarker_height = 7").stands[0].leds(40.0) == (7.0, 1.0)
    assert world(wall="height = 1000").blocks[0].height == 1000
    for stand, wall, says in [("height = 0.5", "", "stands[0].height: 0.5 is outside 1..1000"),
                              ("marker_height = 6.9", "", "stands[0].marker_height: 6.9 is "
                               "outside 7..1000"),
                              ("", "height = 1001", "walls[0].height: 1001 is outside "
                               "1..1000")]:
        with pytest.raises(WorldError, match=says.replace(".", r"\.").replace("[", r"\[")):
            world(stand=stand, wall=wall)


def test_the_spec_gives_each_height_its_range() -> None:
    spec = (Path(__file__).resolve().parents[2] / "spec" / "simulator.md").read_text()
    for table, schema in (("stands", StandTable), ("walls", WallTable),
                          ("obstacles", ObstacleTable)):
        info = mi.type_info(schema)
        assert isinstance(info, mi.StructType)
        for field in info.fields:
            kinds = field.type.types if isinstance(field.type, mi.UnionType) else (field.type,)
            for kind in kinds:
                if isinstance(kind, mi.Metadata) and field.name.endswith("height"):
                    assert isinstance(kind.type, mi.FloatType)
                    row = next(line for line in spec.splitlines()
                               if line.startswith(f"| {table}.{field.name} |"))
                    assert f"| {kind.type.ge:g}..{kind.type.le:g} |" in row, row
