"""Sweeps (`rl1c sim --runs N --sweep KEY=A:B:N`, compiler/sweep.py): the grid, the
arguments refused with what to write, and the table and heat map on a world whose answer
is known: the goal holds the vehicle within 60 cm of a stand's marker, so a stand moved
further away fails and one near succeeds."""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support.campaigns import Instant, campaign_files
from support.cli import rl1c
from support.hold import CAMERA_TO_MARKER, HOLD_WORLD, WAIT, WITHIN

from rl1.compiler.campaign import Task, run_one, run_world
from rl1.compiler.cli import sim_campaign
from rl1.compiler.executors import Workers
from rl1.compiler.sweep import Axis, check, grid, parse_axis
from rl1.vm.sim.world import decode_world


@pytest.fixture
def hold(tmp_path: Path) -> tuple[Path, Path]:
    return campaign_files(tmp_path, "hold", WAIT, HOLD_WORLD)


# The grid ------------------------------------------------------------------------------


def test_an_axis_runs_from_a_to_b_in_n_points() -> None:
    assert parse_axis("stands.bench.x=-50:50:5") == Axis("stands.bench.x", -50, 50, 5)
    assert Axis("k", -50, 50, 5).offsets() == [-50, -25, 0, 25, 50]
    assert Axis("k", 0.1, 0.3, 3).offsets()[-1] == 0.3  # the last is B exactly
    assert Axis("k", 7, 7, 1).offsets() == [7]


def test_the_grid_takes_the_first_axis_slowest() -> None:
    assert grid([Axis("a", 0, 1, 2), Axis("b", 0, 2, 3)]) == [
        (("a", 0), ("b", 0)), (("a", 0), ("b", 1)), (("a", 0), ("b", 2)),
        (("a", 1), ("b", 0)), (("a", 1), ("b", 1)), (("a", 1), ("b", 2))]
    assert grid([]) == [()]  # no sweep: the campaign's one point


def test_an_axis_names_its_one_point_exactly() -> None:
    assert Axis("k", 0, 1, 3).words(0.5) == "k=0.5:0.5:1"
    third = 1 / 3
    assert parse_axis(Axis("k", 0, 1, 4).words(third)).first == third


@pytest.mark.parametrize(("text", "says"), [
    ("stands.bench.x", "is not KEY=A:B:N"),
    ("stands.bench.x=1:2", "is not KEY=A:B:N"),
    ("stands.bench.x=a:2:3", "A and B are numbers"),
    ("stands.bench.x=nan:2:3", "A and B are finite numbers"),
    ("stands.bench.x=0:2:0", "N is the number of points"),
    ("stands.bench.x=0:2:1", "N is the number of points, 1 \\(with A equal to B\\)"),
    ("stands.bench.x=0:2:99999999", "N is the number of points"),
])
def test_a_wrong_axis_says_what_to_write(text: str, says: str) -> None:
    with pytest.raises(ValueError, match=says):
        parse_axis(text)


@pytest.mark.parametrize(("axes", "says"), [
    (["stands.bench.x=0:1:2"] * 2, "stands.bench.x is swept twice"),
    (["start.x=0:1:2", "start.y=0:1:2", "start.heading=0:1:2"], "at most 2 parameters"),
    (["stands.desk.x=0:1:2"], 'stands.desk.x: no stand is named "desk"; name one of '
                              '"bench"'),
    (["vehicle.image_width=0:1:2"], "vehicle.image_width: a whole number"),
    (["floor.x=0:1:2"], "names no parameter; a key is start.x"),
    (["start.x=-300:0:2"], r"start.x: 200 moved by -300 is -100, outside 0..1000"),
    (["start.x=0:9000:2"], r"start.x: 200 moved by \+9000 is 9200, outside 0..1000"),
    (["start.x=0:1:101", "start.y=0:1:101"], "more than 10,000 points"),
])
def test_a_sweep_the_world_cannot_take_is_refused(axes: list[str], says: str) -> None:
    world = decode_world(HOLD_WORLD.encode(), "w.toml")
    with pytest.raises(ValueError, match=says):
        check(world, [parse_axis(axis) for axis in axes])


def test_a_sweep_that_leaves_a_vary_draw_no_room_is_refused() -> None:
    world = decode_world((HOLD_WORLD + "[vary]\nstart.x = { uniform = [-100, 100] }\n")
                         .encode(), "w.toml")
    with pytest.raises(ValueError, match=r"start.x moved by \+750: \[vary\] start.x: offsets "
                                         r"-100\.\.100 would leave the value's range"):
        check(world, [parse_axis("start.x=0:750:2")])
    check(world, [parse_axis("start.x=0:700:2")])  # 900 + 100 is on the floor


def test_a_run_at_a_point_records_the_values_of_the_parameters_swept() -> None:
    task = Task(WAIT, HOLD_WORLD.encode(), "w.toml", offsets=(("stands.bench.x", 15.0),))
    record = run_one(task, 0)
    assert record.varied == (("stands.bench.x", 305.0),)
    assert record.to_json()["varied"] == {"stands.bench.x": 305.0}


# The command line ----------------------------------------------------------------------

_ROW = re.compile(r"^\s+([+-][0-9.]+)\s+(?:([+-][0-9.]+)\s+)?(\d+)/(\d+)\s+[0-9.]+%\s+",
                  re.MULTILINE)


def test_a_sweep_s_table_succeeds_exactly_where_the_stand_is_near(
        hold: tuple[Path, Path], tmp_path: Path) -> None:
    program, world = hold
    out = tmp_path / "runs.jsonl"
    result = rl1c("sim", program, "--world", world, "--runs", "3", "--jobs", "1",
                  "--sweep", "stands.bench.x=0:45:4", "--out", out)
    assert result.exit_code == 0, result.output
    rows = _ROW.findall(result.stdout)
    assert [(float(x), int(successes), int(runs)) for x, _, successes, runs in rows] == [
        (x, 3 if CAMERA_TO_MARKER + x <= WITHIN else 0, 3) for x in (0, 15, 30, 45)]
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    # Point by point, the same seeds at each, each line with the stand where it was.
    assert [(line["seed"], line["varied"]) for line in lines] == [
        (seed, {"stands.bench.x": 290.0 + x}) for x in (0, 15, 30, 45) for seed in range(3)]
    assert "the weakest point's campaign alone" in result.stdout
    assert "so each point is one outcome counted N times" in result.stdout  # no noise


def test_two_parameters_give_a_heat_map_of_the_known_answer(hold: tuple[Path, Path]) -> None:
    program, world = hold
    result = rl1c("sim", program, "--world", world, "--runs", "2", "--jobs", "1",
                  "--sweep", "stands.bench.x=0:40:3", "--sweep", "stands.bench.y=-40:40:3")
    assert result.exit_code == 0, result.output
    heat = result.stdout.split("success rate (%)", 1)[1].splitlines()[2:5]
    for row, x in zip(heat, (0, 20, 40), strict=True):
        rates = [int(cell) for cell in row.split()[1:]]
        assert rates == [100 if math.hypot(CAMERA_TO_MARKER + x, y) <= WITHIN else 0
                         for y in (-40, 0, 40)], row


def test_a_run_at_one_point_is_the_campaign_s_run(hold: tuple[Path, Path],
                                                  tmp_path: Path) -> None:
    program, world = hold
    out = tmp_path / "runs.jsonl"
    assert rl1c("sim", program, "--world", world, "--runs", "1", "--jobs", "1",
                "--sweep", "stands.bench.x=30:30:1", "--out", out).exit_code == 0
    line = json.loads(out.read_text())
    single = rl1c("sim", program, "--world", world, "--seed", "0", "--sweep",
                  "stands.bench.x=30:30:1", "--format", "json")
    assert single.exit_code == line["exit_status"] == 20
    assert json.loads(single.stdout)["status"]["code"] == line["outcome"] == "goal-missed"


def test_each_point_after_the_first_starts_with_tasks_sized_by_the_runs_before(
        hold: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch) -> None:
    instant = Instant()  # its runs take no time: once timed, a task makes the most runs

    @contextmanager
    def two_workers(jobs: int, scheduler: str | None, *,
                    lost: Callable[[], None] | None = None,
                    unmanned: Callable[[], None] | None = None) -> Iterator[Workers]:
        yield Workers(instant, 2)

    monkeypatch.setattr(sim_campaign, "workers", two_workers)
    program, world = hold
    result = rl1c("sim", program, "--world", world, "--runs", "40", "--jobs", "2",
                  "--sweep", "stands.bench.x=0:15:2")
    assert result.exit_code == 0, result.output
    first = [seeds for seeds, point in zip(instant.submitted, instant.points, strict=True)
             if point == (("stands.bench.x", 0.0),)]
    second = [seeds for seeds, point in zip(instant.submitted, instant.points, strict=True)
              if point == (("stands.bench.x", 15.0),)]
    assert first[0] == (0,)  # nothing timed yet: a run a task
    assert second == [tuple(range(40))]  # one task, where it began with 16 of a run


@pytest.mark.parametrize(("args", "says"), [
    (["--sweep", "stands.bench.x=0:40:3"], "--sweep of more than one point is for a "
                                           "campaign: give --runs N"),
    (["--runs", "2", "--sweep", "stands.bench.q=0:40:3"],
     "--sweep: stands.bench.q: unknown key; expected one of x, y, facing"),
    (["--runs", "2", "--sweep", "x"], "--sweep: `x` is not KEY=A:B:N"),
])
def test_the_command_line_refuses_a_wrong_sweep(hold: tuple[Path, Path], args: list[str],
                                                says: str) -> None:
    program, world = hold
    result = rl1c("sim", program, "--world", world, *args)
    assert result.exit_code == 2
    assert says in result.stderr


KEYS = ["start.x", "start.y", "start.heading", "stands.bench.x", "stands.bench.facing",
        "stands.desk.x", "vehicle.k1", "vehicle.trace_interval", "vehicle.image_width",
        "noise.slip", "noise.odometry", "floor.x", "stands.x"]
offset = st.one_of(st.floats(-100, 100), st.floats(-1e7, 1e7), st.sampled_from(
    [0.0, math.inf, math.nan]))


@given(st.lists(st.tuples(st.sampled_from(KEYS), offset, offset, st.integers(0, 4)),
                max_size=3), st.integers(0, 2**32 - 1))
def test_any_sweep_is_refused_or_moves_every_point_within_range(
        axes: list[tuple[str, float, float, int]], seed: int) -> None:
    world = decode_world((HOLD_WORLD + "[vary]\nstart.x = { normal = [0, 5] }\n").encode(),
                         "w.toml")
    try:
        parsed = [parse_axis(f"{key}={first!r}:{last!r}:{count}")
                  for key, first, last, count in axes]
        check(world, parsed)
    except ValueError:
        return
    for point in grid(parsed):
        moved, values = run_world(world, point, seed)
        for key, value in values.items():
            parameter = world.parameter(key)
            assert parameter.low <= value <= parameter.high
            assert moved.parameter(key).value == value
