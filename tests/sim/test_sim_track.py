"""The record of a run stays bounded whatever the world asks for (spec/simulator.md, "The
record of a run"): the track is decimated to a fixed number of points per second of
simulated time and thinned past its cap, the recent poses of the sensor delay answer as
the whole record would, a flood of events is counted past its cap, and a replay page
lists a bounded number of calls. What the pictures and the JSON show exactly (the start,
the end, the events) stays exact."""

from __future__ import annotations

import bisect
import json
from dataclasses import replace
from itertools import accumulate, pairwise
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st
from support.cli import rl1c
from support.worlds import open_floor

from rl1.vm.sim.device import SimDevice, SimEntry
from rl1.vm.sim.motion import Pose
from rl1.vm.sim.render import REPLAY_CALLS, describe_call, html
from rl1.vm.sim.simulator import MAX_EVENTS, Simulator
from rl1.vm.sim.track import MAX_TRACK_POINTS, POINTS_PER_SECOND, History, Track

SPACING = 1 / POINTS_PER_SECOND
gaps = st.lists(st.floats(0.0, 0.2), min_size=1, max_size=300)


def _pose(number: int) -> Pose:
    return Pose(float(number), 0.0, 0.0)


@given(gaps)
def test_the_track_keeps_the_start_the_present_and_points_a_spacing_apart(
        steps: list[float]) -> None:
    track = Track(_pose(-1))
    times = list(accumulate(steps))
    for number, time in enumerate(times):
        track.add(time, _pose(number))
    kept = track.points
    assert kept[0] == (0.0, _pose(-1))
    assert kept[-1] == (times[-1], _pose(len(times) - 1))
    assert set(kept[1:]) <= {(time, _pose(n)) for n, time in enumerate(times)}
    between = [later[0] - earlier[0] for earlier, later in pairwise(kept[:-1])]
    assert all(gap >= SPACING - 1e-9 for gap in between)
    # Each dropped point lies within a spacing of a kept one before it.
    kept_times = [time for time, _ in kept]
    for time in times:
        assert time - kept_times[bisect.bisect_right(kept_times, time) - 1] < SPACING


def test_a_long_run_thins_the_track_to_its_cap_at_an_even_rate() -> None:
    track = Track(_pose(-1))
    total = 3 * MAX_TRACK_POINTS * SPACING  # simulated seconds, at 100 steps a second
    steps = round(total * 100)
    for number in range(1, steps + 1):
        track.add(number / 100, _pose(number))
    kept = track.points
    assert MAX_TRACK_POINTS // 2 <= len(kept) <= MAX_TRACK_POINTS
    assert kept[0][1] == _pose(-1) and kept[-1][1] == _pose(steps)
    assert track.spacing == 4 * SPACING
    gaps_kept = [later[0] - earlier[0] for earlier, later in pairwise(kept[:-1])]
    assert min(gaps_kept) >= track.spacing - 1e-9 and max(gaps_kept) <= 2 * track.spacing


@given(gaps, st.lists(st.floats(0.0, 0.3), min_size=1, max_size=50), st.floats(0.0, 2.0))
def test_the_delayed_pose_is_the_last_recorded_at_or_before_then(
        steps: list[float], waits: list[float], delay: float) -> None:
    history = History(_pose(-1))
    times = [0.0, *accumulate(steps)]
    record = [_pose(-1), *(_pose(n) for n in range(len(steps)))]
    for time, pose in zip(times[1:], record[1:], strict=True):
        history.add(time, pose)
    for now in accumulate(waits):
        # What the simulator looked up before the record was bounded: the whole of it.
        index = bisect.bisect_right(times, now - delay) - 1
        assert history.at(now - delay) == record[max(index, 0)]


def test_a_short_tracing_interval_does_not_grow_the_track_with_the_steps() -> None:
    device = SimDevice(open_floor(x=100.0, trace_interval=1e-3))
    device.move(2, 2)
    device.wait(100)  # 10 s: 10,000 ticks of the tracing timer, and as many steps
    assert len(device.sim.track) <= 10 * POINTS_PER_SECOND + 2
    assert device.sim.track[-1] == (device.sim.time, device.sim.pose)


def test_a_flood_of_events_is_counted_past_its_cap_and_the_ending_still_recorded() -> None:
    sim = Simulator(open_floor())
    for _ in range(MAX_EVENTS + 5):
        sim.note("lost", "line lost during MOV in mode 1")
    sim.note("end", "the program ended")
    assert len(sim.events) == MAX_EVENTS + 1
    assert sim.events_left_out == 5
    assert sim.events[-1].kind == "end"


WORLD = """[floor]
size = [100000, 1000]
[start]
x = 100.0
y = 500.0
[vehicle]
trace_interval = 0.001
[limits]
time = 30
"""


def test_the_json_and_the_pictures_keep_the_start_the_end_and_the_events(
        tmp_path: Path) -> None:
    world = tmp_path / "long.world.toml"
    world.write_text(WORLD)
    program = tmp_path / "drive.rob"
    program.write_text("(MOV 2,2)\n:10 (TIM 100); #10\n")
    svg, html = tmp_path / "run.svg", tmp_path / "run.html"
    result = rl1c("sim", program, "--world", world, "--format", "json", "--svg", svg,
                  "--html", html)
    assert result.exit_code == 13  # the time limit
    document = json.loads(result.stdout)
    track = document["track"]
    assert len(track) <= 30 * POINTS_PER_SECOND + 2  # 30,000 steps
    assert track[0] == [0, 100.0, 500.0, 0]
    assert track[-1][1:] == [*document["status"]["pose"]]
    assert [event["kind"] for event in document["events"]] == ["fault"]
    assert document["events"][0]["pose"] == document["status"]["pose"][:2]
    assert svg.stat().st_size < 50_000 and html.stat().st_size < 100_000


def test_the_default_step_keeps_every_point_of_a_short_run() -> None:
    device = SimDevice(replace(open_floor(x=100.0), time_limit=60.0))
    device.move(2, 2)
    device.wait(20)  # 40 steps of 0.05 s, each a tick of the tracing timer
    times = [time for time, _ in device.sim.track]
    assert len(times) == 41 and times[-1] == device.sim.time


def test_a_replay_page_lists_the_first_and_last_calls_of_a_long_run() -> None:
    world = open_floor()
    calls = [SimEntry(number / 1000, "LMP", (number,), None, _pose(0), 1)
             for number in range(25_000)]
    page = html(world, [(0.0, _pose(0))], [], calls)
    listed = json.loads(page.split("const run = ", 1)[1].split(";\n", 1)[0])["log"]
    half = REPLAY_CALLS // 2
    assert len(listed) == REPLAY_CALLS + 1
    assert [text for *_, text in listed[:half]] == [describe_call(c) for c in calls[:half]]
    assert [text for *_, text in listed[half + 1:]] == [describe_call(c)
                                                       for c in calls[-half:]]
    assert listed[half] == [calls[half].time, "call", None,
                            f"... {25_000 - REPLAY_CALLS:,} calls left out ..."]
