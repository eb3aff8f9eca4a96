"""The pictures of a run (vm/sim/render.py): the SVG is exact XML and shows a scale, a
legend, the features' names, the start, the heading at each outline, turns in place, the
camera's footprint and the ultrasonic cones; the replay page carries the log with lost
lines, handlers and source lines, the camera's frames and the plots. The page's
behaviour in a browser is tests/browser/'s."""

from __future__ import annotations

import base64
import json
import math
import re
import xml.etree.ElementTree as ElementTree
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from support.pictures import HANDLER_LINE, SCAN, draw
from support.worlds import open_floor

from rl1.vm.sim.camera import View, view_centre, view_of
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.motion import Pose
from rl1.vm.sim.render import (
    FAR,
    MAX_FRAMES,
    MAX_PLOTTED,
    footprint,
    html,
    turns_in_place,
    wheel_speeds,
)
from rl1.vm.sim.sightings import MAX_SIGHTINGS, Sighting, Sightings

SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def pictures(tmp_path_factory: pytest.TempPathFactory) -> tuple[ElementTree.Element, str]:
    picture, page = draw(tmp_path_factory.mktemp("pictures"))
    return ElementTree.fromstring(picture.read_text()), page.read_text()


def _texts(element: ElementTree.Element) -> list[str]:
    return [text.text or "" for text in element.iter(f"{SVG}text")]


def _by_class(root: ElementTree.Element, tag: str, name: str) -> list[ElementTree.Element]:
    return [element for element in root.iter(f"{SVG}{tag}")
            if name in element.get("class", "").split()]


def _points(element: ElementTree.Element) -> list[tuple[float, float]]:
    return [(float(x), float(y)) for x, y in
            (pair.split(",") for pair in element.get("points", "").split())]


def replay_data(page: str) -> dict[str, Any]:
    data: dict[str, Any] = json.loads(
        page.split("const run = ", 1)[1].split(";\n", 1)[0])
    return data


def test_the_legend_names_every_kind_of_mark(
        pictures: tuple[ElementTree.Element, str]) -> None:
    root, _ = pictures
    legend = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "legend")
    assert {"path", "start", "end pose", "run ended", "turn in place", "camera at each IMG",
            "ultrasonic echo", "line lost", "line found", "handler taken", "fault",
            "wall, obstacle", "stand, marker"} <= set(_texts(legend))


def test_the_scale_bar_is_as_long_as_it_says(
        pictures: tuple[ElementTree.Element, str]) -> None:
    root, _ = pictures
    scale = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "scale")
    bar = next(scale.iter(f"{SVG}line"))
    floor = next(root.iter(f"{SVG}rect"))
    assert float(floor.get("width", "")) == 800  # the floor: 800 cm, drawn 1 px a cm
    assert _texts(scale) == ["200 cm"]
    assert float(bar.get("x2", "")) - float(bar.get("x1", "")) == 200


def test_lines_marks_stands_walls_and_the_start_are_labelled(
        pictures: tuple[ElementTree.Element, str]) -> None:
    root, _ = pictures
    labels = [text.text for text in _by_class(root, "text", "label")]
    for name in ("guide", "branch", "stand", "east wall", "start"):
        assert name in labels


def test_each_outline_has_a_heading_arrow_along_the_pose(
        pictures: tuple[ElementTree.Element, str]) -> None:
    root, _ = pictures
    headings = _by_class(root, "polyline", "heading")
    assert len(headings) >= 3  # outlines along the way, the start, the end
    for heading in headings:
        (x0, y0), (x1, y1) = _points(heading)
        assert math.dist((x0, y0), (x1, y1)) == pytest.approx(52, abs=0.2)  # 80 / 2 + 12
        assert heading.get("marker-end") == "url(#arrow)"
    # The start and the end face +x (the scan turns back to 0, the tracing holds it).
    start, end = _by_class(root, "g", "pose")[-2:]
    for pose in (start, end):
        (x0, y0), (x1, y1) = _points(_by_class(pose, "polyline", "heading")[0])
        assert x1 - x0 == pytest.approx(52, abs=0.5) and y1 == pytest.approx(y0, abs=0.5)
    assert _points(_by_class(start, "polyline", "heading")[0])[0] == (80.0, 380.0)


def test_the_scan_in_place_is_drawn_as_three_turns(
        pictures: tuple[ElementTree.Element, str]) -> None:
    root, _ = pictures
    turns = _by_class(root, "g", "turn")
    assert [_texts(turn) for turn in turns] == [[f"{angle:+d}°"] for angle in SCAN]


def test_each_image_has_a_footprint_and_each_ultrasonic_reading_a_cone(
        pictures: tuple[ElementTree.Element, str]) -> None:
    root, _ = pictures
    assert len(_by_class(root, "polygon", "footprint")) == 2  # two (IMG)s
    first, second = _by_class(root, "g", "ultrasonic")
    # Nothing in range at the start: a dashed ray, no echo; then the wall's echo.
    assert "100 cm" in "".join(first.itertext()) and not list(first.iter(f"{SVG}circle"))
    assert "92 cm" in "".join(second.itertext()) and list(second.iter(f"{SVG}circle"))


def test_the_lost_line_and_the_handler_are_marked_on_the_plan(
        pictures: tuple[ElementTree.Element, str]) -> None:
    root, _ = pictures
    assert len(_by_class(root, "circle", "lost")) == 1
    assert len(_by_class(root, "circle", "handler")) == 1


def test_the_replay_log_has_the_lost_line_the_handler_and_source_lines(
        pictures: tuple[ElementTree.Element, str]) -> None:
    _, page = pictures
    log = replay_data(page)["log"]
    kinds = [kind for _, kind, _, _ in log]
    assert "lost" in kinds and "handler" in kinds
    assert [time for time, *_ in log] == sorted(time for time, *_ in log)
    after = [entry for entry in log[kinds.index("handler"):] if entry[1] == "call"]
    assert after[0][2] == HANDLER_LINE and after[0][3] == "MOV 0,0"
    assert all(isinstance(line, int) for _, kind, line, _ in log if kind == "call")


def test_the_replay_frames_are_the_images_the_camera_saw(
        pictures: tuple[ElementTree.Element, str]) -> None:
    _, page = pictures
    frames = replay_data(page)["frames"]
    assert len(frames) == 2
    columns, rows, bits, window, reading = (frames[0][key] for key in (
        "columns", "rows", "bits", "window", "reading"))
    assert isinstance(bits, str) and isinstance(columns, int) and isinstance(rows, int)
    image = np.unpackbits(np.frombuffer(base64.b64decode(bits), dtype=np.uint8))
    # The line across the window: the set pixels are the area IMG returned.
    assert int(image[:columns * rows].sum()) == reading[0] == 156
    assert window == [98, 117, 158, 123] and frames[1]["reading"][0] == 0  # the line lost at last


def test_the_page_holds_the_plots_and_nothing_from_outside(
        pictures: tuple[ElementTree.Element, str]) -> None:
    _, page = pictures
    assert page.count('class="plot"') == 4
    for outside in ("http://", "https://", "<link", "src="):
        assert outside not in page.replace('xmlns="http://www.w3.org/2000/svg"', "")


def test_a_replay_page_holds_a_bounded_number_of_frames() -> None:
    world = open_floor()
    view = view_of(500, 500, 0.0, 392, math.radians(50), world.vehicle)
    sightings = [Sighting(i / 10, 0, view, (0, 0, 0)) for i in range(1000)]
    frames = replay_data(html(world, [(0.0, Pose(500, 500, 0))], [], [], "",
                              sightings))["frames"]
    assert len(frames) <= MAX_FRAMES
    assert frames[0]["time"] == 0 and frames[-1]["time"] > 99 - 100 / MAX_FRAMES


def test_sightings_keep_the_first_and_the_last() -> None:
    view = View(0, 0, 40, 0, -1)
    kept = Sightings()
    for i in range(MAX_SIGHTINGS + 7):
        kept.add(Sighting(float(i), 0, view, (i, 0, 0)))
    times = [sighting.time for sighting in kept]
    assert len(kept) == MAX_SIGHTINGS and kept.left_out == 7
    assert times[0] == 0 and times[-1] == MAX_SIGHTINGS + 6
    assert times[MAX_SIGHTINGS // 2] == MAX_SIGHTINGS // 2 + 7


def test_a_downward_footprint_surrounds_where_the_axis_meets_the_floor() -> None:
    world = open_floor()
    view = view_of(500, 500, 0.3, 392, math.radians(50), world.vehicle)
    corners = footprint(view, world)
    centre = view_centre(view)
    assert centre is not None
    # Symmetric about the optical axis: the near and far edges' mid-points lie on it.
    for a, b in ((corners[0], corners[1]), (corners[2], corners[3])):
        mx, my = (a[0] + b[0]) / 2, (a[1] + b[1]) / 2
        assert math.atan2(my - view.y, mx - view.x) == pytest.approx(view.yaw)
    near = math.dist((view.x, view.y), ((corners[0][0] + corners[1][0]) / 2,
                                        (corners[0][1] + corners[1][1]) / 2))
    far = math.dist((view.x, view.y), ((corners[2][0] + corners[3][0]) / 2,
                                       (corners[2][1] + corners[3][1]) / 2))
    assert near < math.dist((view.x, view.y), centre[:2]) < far


def test_a_level_camera_sees_the_floor_up_to_the_cut() -> None:
    world = open_floor()
    view = view_of(500, 500, 0.0, 392, 0.0, world.vehicle)
    far_corners = footprint(view, world)[2:]
    assert all(math.dist((view.x, view.y), corner) == pytest.approx(FAR)
               for corner in far_corners)


@given(st.lists(st.integers(3, 170), min_size=1, max_size=6))
def test_turns_in_place_are_found_each_way(sizes: list[int]) -> None:
    angles = [size * (-1) ** i for i, size in enumerate(sizes)]  # left, right, left...
    device = SimDevice(open_floor())
    for angle in angles:
        device.rotate(angle)
    found = turns_in_place(device.sim.track, device.trace)
    assert [math.degrees(turned) for _, turned in found] == pytest.approx(angles)
    assert all(start.heading == pytest.approx(math.radians(sum(angles[:i])))
               for i, (start, _) in enumerate(found))


def test_a_turn_on_opposite_wheels_is_read_from_the_track() -> None:
    device = SimDevice(open_floor())
    device.move(-2, 2)  # 20 cm/s of tread 50: 0.4 rad/s, left
    device.wait(30)
    device.move(2, -2)
    device.wait(10)
    device.hold()
    (first, left), (second, right) = turns_in_place(device.sim.track, device.trace)
    assert left == pytest.approx(1.2, abs=0.03) and right == pytest.approx(-0.4, abs=0.03)
    assert first.heading == 0 and second.heading == pytest.approx(1.2, abs=0.03)


def test_wheel_speeds_from_the_track() -> None:
    device = SimDevice(open_floor())
    device.move(2, 4)
    device.wait(20)
    device.rotate(90)
    speeds = wheel_speeds(device.sim.world, device.sim.track)
    moving = [(left, right) for time, left, right in speeds if time <= 2.0]
    turning = [(left, right) for time, left, right in speeds if time > 2.05]
    assert all(left == pytest.approx(2) and right == pytest.approx(4) for left, right in moving)
    rotate = device.sim.world.vehicle.rotate_speed
    assert turning and all(left == pytest.approx(-rotate) and right == pytest.approx(rotate)
                           for left, right in turning)


def test_a_run_on_the_sample_world_draws_valid_xml(tmp_path: Path) -> None:
    # Every name is escaped: a world's names may hold <, & and quotes.
    from support.cli import rl1c
    examples = Path(__file__).parents[2] / "examples"
    world = tmp_path / "w.toml"
    world.write_text((examples / "sample.world.toml").read_text().replace(
        '"guide"', '"a <b> & \\"c\\""'))
    picture = tmp_path / "s.svg"
    result = rl1c("sim", examples / "sample.rob", "--world", world, "--svg", picture)
    assert picture.exists(), result.output
    root = ElementTree.fromstring(picture.read_text())
    assert 'a <b> & "c"' in [text.text for text in _by_class(root, "text", "label")]


def test_a_polling_loop_plots_a_bounded_number_of_points(tmp_path: Path) -> None:
    from support.cli import rl1c
    program, world, page = tmp_path / "poll.rob", tmp_path / "w.toml", tmp_path / "poll.html"
    program.write_text("(MOV 1,1)\n:10 (KYO); (ULT A); #10\n")
    world.write_text("[floor]\nsize = [2000, 500]\n[start]\nx = 100\ny = 250\n"
                     "[limits]\ntime = 100\n")
    result = rl1c("sim", program, "--world", world, "--html", page)
    assert result.exit_code == 13, result.output  # the time limit, 5,000 readings on
    plotted = re.findall(r'class="series" points="([^"]*)"', page.read_text())
    # ULT A; KYO's centre, right and left; both wheels: each a staircase or a line.
    assert len(plotted) == 6
    assert all(0 < len(points.split()) <= 2 * MAX_PLOTTED + 1 for points in plotted)


def test_a_name_cannot_end_the_page_s_script(tmp_path: Path) -> None:
    from support.cli import rl1c
    program, world, page = tmp_path / "hit.rob", tmp_path / "w.toml", tmp_path / "hit.html"
    program.write_text("(MOV 3,3); (TIM 100)\n")
    world.write_text('[floor]\nsize = [800, 500]\n[start]\nx = 100\ny = 250\n[[walls]]\n'
                     'name = "</script><b>"\npoints = [[300, 0], [320, 0], [320, 500]]\n')
    result = rl1c("sim", program, "--world", world, "--html", page)
    assert result.exit_code == 0, result.output  # ran on into the wall, named in an event
    text = page.read_text()
    assert text.count("</script>") == 1  # the page's own, at its end
    assert "&lt;/script&gt;&lt;b&gt;" in text  # the wall's label
    assert text.count("<b>") == text.count("<\\/script><b>") == 1  # in the script's data
    assert "</script><b>" in json.dumps(replay_data(text)["log"])  # the JSON holds it whole
