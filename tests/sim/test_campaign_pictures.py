"""Pictures of a campaign (`rl1c sim --runs N --svg/--html`, vm/sim/campaign_render.py):
valid SVG and HTML with one path per run and a mark for each failure where its JSON
line says it ended, coloured by its kind; a sweep's heat map; and what a picture keeps
of a campaign is bounded whatever its size."""

from __future__ import annotations

import dataclasses
import json
import xml.etree.ElementTree as ElementTree
from html.parser import HTMLParser
from pathlib import Path
from typing import cast

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support.campaigns import campaign_files
from support.cli import rl1c
from support.hold import HOLD_WORLD, TURN

from rl1.compiler.campaign import Task, run_one, thinned
from rl1.vm.sim.campaign_render import MAX_MARKS, MAX_PATHS, Overlay, Run
from rl1.vm.sim.motion import Pose
from rl1.vm.sim.render import MARGIN, TOP

# A stand drawn 0 to 45 cm back from 40 cm ahead of the camera: the goal holds within
# 60 cm, so some runs miss it (goal-missed); and a fence just right of the vehicle
# stops those whose start is drawn near it as the vehicle turns (a collision).
WORLD = HOLD_WORLD.replace("[goal]", """\
[[obstacles]]
name = "fence"
points = [[100, 445], [400, 445], [400, 450], [100, 450]]
[goal]""") + """\
[vary]
stands.bench.x = { uniform = [0, 45] }
start.y = { uniform = [-40, 0] }
"""
RUNS = 24
SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def campaign(tmp_path_factory: pytest.TempPathFactory
             ) -> tuple[ElementTree.Element, str, list[dict[str, object]]]:
    folder = tmp_path_factory.mktemp("pictures")
    program, world = campaign_files(folder, "p", TURN, WORLD)
    picture, page, out = folder / "c.svg", folder / "c.html", folder / "c.jsonl"
    result = rl1c("sim", program, "--world", world, "--runs", str(RUNS), "--jobs", "1",
                  "--svg", picture, "--html", page, "--out", out)
    assert result.exit_code == 0, result.output
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    return ElementTree.fromstring(picture.read_text()), page.read_text(), lines


def _kind(line: dict[str, object]) -> str:
    return str(line["safety"] or line["outcome"])


def test_the_campaign_has_successes_and_failures_of_two_kinds(
        campaign: tuple[ElementTree.Element, str, list[dict[str, object]]]) -> None:
    _, _, lines = campaign
    assert {_kind(line) for line in lines if not line["success"]} == {"goal-missed",
                                                                      "collision"}
    assert any(line["success"] for line in lines)


def test_every_run_has_one_path(
        campaign: tuple[ElementTree.Element, str, list[dict[str, object]]]) -> None:
    picture, _, lines = campaign
    paths = picture.findall(f".//{SVG}polyline[@class='run']")
    assert sorted(int(path.get("data-seed", "")) for path in paths) == [
        line["seed"] for line in lines]
    for path in paths:
        points = (path.get("points") or "").split()
        assert 2 <= len(points) <= 64


def test_each_failure_is_marked_where_its_line_says_it_ended_with_its_kind(
        campaign: tuple[ElementTree.Element, str, list[dict[str, object]]]) -> None:
    picture, _, lines = campaign
    marks = picture.findall(f".//{SVG}circle[@class='failure']")
    failed = {int(str(line["seed"])): line for line in lines if not line["success"]}
    assert sorted(int(mark.get("data-seed", "")) for mark in marks) == sorted(failed)
    colours: dict[str, set[str]] = {}
    for mark in marks:
        line = failed[int(mark.get("data-seed", ""))]
        assert mark.get("data-kind") == _kind(line)
        x, y, _ = cast(list[float], line["pose"])
        assert float(mark.get("cx", "")) == pytest.approx(MARGIN + x, abs=0.06)
        assert float(mark.get("cy", "")) == pytest.approx(TOP + 1000 - y, abs=0.06)
        colours.setdefault(_kind(line), set()).add(mark.get("fill", ""))
    assert all(len(fills) == 1 for fills in colours.values())  # one colour a kind
    assert len(set.union(*colours.values())) == len(colours)  # and each its own


def test_the_legend_counts_each_kind(
        campaign: tuple[ElementTree.Element, str, list[dict[str, object]]]) -> None:
    picture, _, lines = campaign
    legend = " ".join(text.text or "" for text in picture.iter(f"{SVG}text"))
    for kind in ("goal-missed", "collision"):
        count = sum(1 for line in lines if not line["success"] and _kind(line) == kind)
        assert f"{kind}: {count} run" in legend
    assert f"{RUNS} paths of {RUNS} runs" in legend
    assert "the world as written; each run moves start.y, stands.bench.x" in legend


class _Page(HTMLParser):
    """The page's elements as they open and close, and its text."""

    def __init__(self) -> None:
        super().__init__()
        self.open: list[str] = []
        self.seen: list[str] = []
        self.text = ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.seen.append(tag)
        if tag not in ("meta", "polyline", "circle", "rect", "line", "polygon", "path"):
            self.open.append(tag)

    def handle_startendtag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.seen.append(tag)

    def handle_endtag(self, tag: str) -> None:
        if tag in ("polyline", "circle", "rect", "line", "polygon", "path"):
            return
        assert self.open.pop() == tag

    def handle_data(self, data: str) -> None:
        self.text += data


def test_the_page_is_whole_html_with_the_picture_and_the_summary(
        campaign: tuple[ElementTree.Element, str, list[dict[str, object]]]) -> None:
    picture, page, lines = campaign
    parsed = _Page()
    parsed.feed(page)
    parsed.close()
    assert parsed.open == []  # every element closed
    assert parsed.seen.count("svg") == 1
    assert parsed.seen.count("polyline") == len(picture.findall(f".//{SVG}polyline"))
    successes = sum(1 for line in lines if line["success"])
    assert f"success: {successes} of {RUNS}" in parsed.text
    assert "http" not in page.replace("http://www.w3.org/2000/svg", "")  # offline


def test_a_sweep_s_picture_is_its_heat_map(tmp_path: Path) -> None:
    program, world = campaign_files(tmp_path, "p", TURN, WORLD.split("[vary]")[0])
    picture = tmp_path / "h.svg"
    result = rl1c("sim", program, "--world", world, "--runs", "2", "--jobs", "1",
                  "--sweep", "stands.bench.x=0:40:2", "--sweep", "start.y=0:10:3",
                  "--svg", picture)
    assert result.exit_code == 0, result.output
    cells = ElementTree.fromstring(picture.read_text()).findall(f".//{SVG}g[@class='cell']")
    assert len(cells) == 6
    assert [(int(cell.get("data-successes", "")), int(cell.get("data-runs", "")))
            for cell in cells] == [(2, 2)] * 3 + [(0, 2)] * 3  # the near stand succeeds


# Bounded memory ---------------------------------------------------------------------------


def test_a_picture_keeps_a_bounded_sample_of_a_large_campaign() -> None:
    total = 10_000
    overlay = Overlay()
    path = tuple((float(i), 0.0) for i in range(64))
    for seed in range(total):
        overlay.add(Run(seed, path, (0.0, 0.0), "collision" if seed % 3 == 0 else None))
    assert MAX_PATHS // 2 <= len(overlay.paths) <= MAX_PATHS
    assert [run.seed for run in overlay.paths] == list(range(0, total, overlay.every))
    assert len(overlay.marks) == MAX_MARKS
    assert overlay.kinds == {"collision": 3334}


@given(st.integers(1, 5 * MAX_PATHS))
def test_a_campaign_stopped_at_any_point_shows_paths_spread_over_its_runs(runs: int) -> None:
    # The sample was every ceil(planned / MAX_PATHS)-th run: a campaign of 100,000 runs
    # stopped by Ctrl-C after 300 showed the paths of 2.
    overlay = Overlay()
    for seed in range(runs):
        overlay.add(Run(seed, (), (0.0, 0.0)))
    assert len(overlay.paths) == min(runs, len(range(0, runs, overlay.every)))
    assert min(runs, MAX_PATHS // 2) <= len(overlay.paths) <= MAX_PATHS
    assert [run.seed for run in overlay.paths] == list(range(0, runs, overlay.every))


def test_a_record_carries_a_thinned_path_only_when_asked() -> None:
    task = Task(TURN, WORLD.encode(), "w.toml", budget=1000)
    assert run_one(task, 0).path == ()
    record = run_one(dataclasses.replace(task, path_points=64), 0)
    assert 2 <= len(record.path) <= 64
    assert record.path[-1] == pytest.approx(record.pose[:2], abs=0.06)


def test_thinning_keeps_the_ends_and_at_most_the_points_asked() -> None:
    track = [(i * 0.05, Pose(float(i), 2.0 * i, 0.0)) for i in range(1001)]
    for most in (2, 3, 64, 2000):
        kept = thinned(track, most)
        assert 2 <= len(kept) <= most
        assert kept[0] == (0.0, 0.0)
        assert kept[-1] == (1000.0, 2000.0)
    assert thinned(track, 0) == ()
