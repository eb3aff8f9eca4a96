"""The world's [goal] (vm/sim/goal.py): its schema, its judgement of a run from the exact
steps of the simulator (never the decimated track), and what `rl1c sim` makes of it:
the report, the JSON, the pictures and exit status 20."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import msgspec.inspect as mi
import pytest
from hypothesis import given
from hypothesis import strategies as st
from support.cli import rl1c
from support.worlds import open_floor

from rl1.vm.sim.goal import GOAL_MISSED, Goal, Hold, Region, Step, Verdict, judge
from rl1.vm.sim.motion import Pose
from rl1.vm.sim.simulator import Simulator
from rl1.vm.sim.world import (
    GoalRegionTable,
    GoalTable,
    HoldTable,
    World,
    WorldError,
    decode_world,
)

ROOT = Path(__file__).resolve().parents[2]
SPEED = 30.0  # cm/s: wheel speed 6 at the default 5 cm/s a unit


def box(x0: float, y0: float, x1: float, y1: float) -> tuple[tuple[float, float], ...]:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


def with_goal(goal: Goal, x: float = 60.0, y: float = 150.0, heading: float = 0.0) -> World:
    return replace(open_floor(x, y, heading), goal=goal)


def drive(world: World, seconds: float, left: int = 6, right: int = 6) -> Verdict:
    """Drive at constant wheel speeds for `seconds`, judged online as `rl1c sim` does."""
    sim = Simulator(world)
    judging = world.judge(sim.pose)
    sim.on_move = judging.step
    sim.drive("MOV", left, right)
    sim.run_for(seconds, interruptible=False)
    sim.halt()
    return judging.verdict(sim.time)


# A straight run at a known speed ---------------------------------------------------------


def test_a_straight_run_reaches_a_region_when_its_speed_says() -> None:
    # From x = 60 at 30 cm/s, the centre crosses x = 300 at (300 - 60) / 30 = 8 s.
    world = with_goal(Goal(reach=(Region("gate", box(300, 100, 310, 200)),)))
    [outcome] = drive(world, 10.0).outcomes
    assert outcome.met and outcome.part == "reach" and outcome.name == "gate"
    assert outcome.time == pytest.approx(8.0, abs=1e-9)
    assert outcome.pose is not None and outcome.pose.x == pytest.approx(300.0, abs=1e-9)
    assert outcome.text == "reached at 8.00 s at (300.0, 150.0) heading 0.0"


@pytest.mark.parametrize(("deadline", "met"), [(7.99, False), (8.01, True)])
def test_a_deadline_just_before_or_just_after_the_arrival(deadline: float, met: bool) -> None:
    # The centre arrives at 8 s; the run ends at 8.005 s, between the two deadlines.
    world = with_goal(Goal(reach=(Region("gate", box(300, 100, 310, 200)),),
                           deadline=deadline))
    verdict = drive(world, 8.005)
    reach, ended = verdict.outcomes
    assert verdict.met is met and reach.met is met and ended.met is met
    assert reach.time == pytest.approx(8.0, abs=1e-9)
    assert ended.part == "deadline" and ended.time == pytest.approx(8.005, abs=1e-9)
    if not met:
        assert reach.text.endswith("after the deadline of 7.99 s")
        assert ended.text == "the run ended at 8.01 s, after the deadline of 7.99 s"


def test_a_forbidden_region_crossed_between_two_kept_track_points_is_caught() -> None:
    # At 60 cm/s each step of 0.05 s covers 3 cm: from x = 60 the steps end at 63, 66, ...
    # A strip from x = 61 to 62 holds no step's end, nor any point the track keeps.
    pit = Region("pit", box(61, 100, 62, 200))
    world = with_goal(Goal(avoid=(pit,)))
    sim = Simulator(world)
    judging = world.judge(sim.pose)
    sim.on_move = judging.step
    sim.drive("MOV", 12, 12)
    sim.run_for(1.0, interruptible=False)
    assert not any(61 <= pose.x <= 62 for _, pose in sim.track)
    [outcome] = judging.verdict(sim.time).outcomes
    assert not outcome.met
    assert outcome.time == pytest.approx(1 / 60, abs=1e-9)  # 1 cm at 60 cm/s
    assert outcome.text == "entered at 0.02 s at (61.0, 150.0) heading 0.0"


def test_a_run_that_keeps_out_of_a_region_avoids_it() -> None:
    world = with_goal(Goal(avoid=(Region("pit", box(61, 160, 62, 200)),)))
    [outcome] = drive(world, 2.0, 12, 12).outcomes
    assert outcome.met and outcome.text == "never entered" and outcome.time is None


# Headings, holds and the end --------------------------------------------------------------


def test_a_region_with_a_heading_is_reached_when_the_heading_comes_within_tolerance() -> None:
    # ROT turns in place at 2 x 15 cm/s over a 50 cm tread: 0.6 rad/s; the heading comes
    # within 10 degrees of 90 at 80 degrees.
    region = Region("facing up", box(50, 140, 70, 160), math.radians(90), math.radians(10))
    world = with_goal(Goal(reach=(region,)))
    sim = Simulator(world)
    judging = world.judge(sim.pose)
    sim.on_move = judging.step
    sim.rotate(120)
    [outcome] = judging.verdict(sim.time).outcomes
    assert outcome.met
    assert outcome.time == pytest.approx(math.radians(80) / 0.6, abs=1e-9)


def test_a_region_entered_with_the_wrong_heading_is_missed_and_says_so() -> None:
    region = Region("gate", box(300, 100, 310, 200), math.radians(90), math.radians(10))
    [outcome] = drive(with_goal(Goal(reach=(region,))), 10.0).outcomes
    assert not outcome.met
    assert outcome.text == ("entered at 8.00 s at (300.0, 150.0) heading 0.0, but never with "
                            "the heading within 10 degrees of 90")


def test_a_region_never_reached_says_how_near_the_vehicle_came() -> None:
    world = with_goal(Goal(reach=(Region("far", box(300, 200, 310, 300)),)))
    [outcome] = drive(world, 10.0).outcomes  # along y = 150, 50 cm below it
    assert not outcome.met and outcome.time == pytest.approx(8.0)
    assert outcome.text.startswith("never reached: the nearest the centre came was 50.0 cm "
                                   "away, at 8.00 s at (300.0, 150.0)")


def _hold_world(seconds: float) -> World:
    # The camera is 30 cm ahead of the centre; the marker at x = 200.
    return with_goal(Goal(holds=(Hold("stand", (200.0, 150.0), 50.0, seconds),)), x=0.0)


def test_a_hold_is_met_once_the_vehicle_has_stood_long_enough_near_the_marker() -> None:
    # To x = 130 in 2 s (the camera at 160, 40 cm from the marker), a stop of 1 s, away.
    steps = [Step(0.0, 2.0, Pose(0, 150, 0), Pose(130, 150, 0)),
             Step(3.0, 4.0, Pose(130, 150, 0), Pose(30, 150, 0))]
    [outcome] = judge(_hold_world(0.5).judge(), steps, 4.0).outcomes
    assert outcome.met and outcome.time == 2.5
    assert outcome.text == ("stood still 0.5 s with the camera within 50 cm of its marker "
                            "by 2.50 s at (130.0, 150.0) heading 0.0")
    [short] = judge(_hold_world(1.5).judge(), steps, 4.0).outcomes
    assert not short.met
    assert short.text == ("never stood still 1.5 s with the camera within 50 cm of its "
                          "marker: the nearest stop was 140.0 cm from it, from 4.00 s at "
                          "(30.0, 150.0) heading 0.0")


def test_the_rest_after_the_run_counts_as_standing() -> None:
    steps = [Step(0.0, 2.0, Pose(0, 150, 0), Pose(130, 150, 0))]
    [outcome] = judge(_hold_world(5.0).judge(), steps, 2.0).outcomes
    assert outcome.met and outcome.time == 7.0


def test_the_end_region_judges_the_last_pose_and_its_heading() -> None:
    end = Region("home", box(250, 100, 350, 200), 0.0, math.radians(5))
    steps = [Step(0.0, 8.0, Pose(60, 150, 0), Pose(300, 150, math.radians(7)))]
    world = with_goal(Goal(end=end))
    [turned] = judge(world.judge(), steps, 8.0).outcomes
    assert not turned.met and "in the region, but the heading is more than 5 degrees" in (
        turned.text)
    steps[0] = steps[0]._replace(after=Pose(400, 150, 0))
    [outside] = judge(world.judge(), steps, 8.0).outcomes
    assert outside.text == "ended at 8.00 s at (400.0, 150.0) heading 0.0, 50.0 cm outside " \
                           "the region"
    steps[0] = steps[0]._replace(after=Pose(300, 150, math.radians(-364)))
    assert judge(world.judge(), steps, 8.0).met  # -364 degrees is 4 degrees from 0


@given(st.floats(-300, 300), st.floats(-300, 300), st.integers(1, 40))
def test_the_judgement_does_not_depend_on_how_a_straight_run_is_cut_into_steps(
        dx: float, dy: float, pieces: int) -> None:
    # The same straight motion as one step or as many: the same verdict, the same times.
    goal = Goal(reach=(Region("a", box(20, 20, 60, 40)),),
                avoid=(Region("b", box(-50, -10, -45, 80)),))
    world = with_goal(goal, x=0.0, y=0.0)
    end = Pose(dx, dy, 0.0)

    def at(k: int) -> Pose:
        return Pose(dx * k / pieces, dy * k / pieces, 0.0)

    whole = judge(world.judge(), [Step(0.0, 10.0, at(0), end)], 10.0)
    cut = judge(world.judge(), [Step(10.0 * k / pieces, 10.0 * (k + 1) / pieces, at(k), at(k + 1))
                        for k in range(pieces)], 10.0)
    assert [o.met for o in whole.outcomes] == [o.met for o in cut.outcomes]
    for one, other in zip(whole.outcomes, cut.outcomes, strict=True):
        if one.met or one.part == "avoid":
            assert (one.time is None) == (other.time is None)
            if one.time is not None and other.time is not None:
                assert one.time == pytest.approx(other.time, abs=1e-6)


# The world file ---------------------------------------------------------------------------

WORLD = b"""
[floor]
size = [800, 500]

[start]
x = 60
y = 150

[[stands]]
name = "bench"
x = 400
y = 300
facing = -90

[goal]
deadline = 30

[[goal.reach]]
name = "gate"
points = [[300, 100], [310, 100], [310, 200], [300, 200]]

[[goal.hold]]
stand = "bench"
within = 40

[goal.end]
points = [[450, 100], [550, 100], [550, 200], [450, 200]]
heading = 0
tolerance = 5

[[goal.avoid]]
name = "pit"
points = [[400, 140], [401, 140], [401, 160], [400, 160]]
"""


def test_a_goal_loads_with_its_defaults_and_the_marker_of_its_stand() -> None:
    goal = decode_world(WORLD, "w.toml").goal
    assert goal == Goal(
        reach=(Region("gate", box(300, 100, 310, 200)),),
        holds=(Hold("bench", (400.0, 280.0), 40.0, 0.5),),
        end=Region("end", box(450, 100, 550, 200), 0.0, math.radians(5)),
        avoid=(Region("pit", box(400, 140, 401, 160)),),
        deadline=30.0)
    assert decode_world(WORLD.split(b"[goal]")[0], "w.toml").goal is None


@pytest.mark.parametrize(("text", "expected"), [
    (WORLD.replace(b'stand = "bench"', b'stand = "bech"'),
     'w.toml:23: goal.hold[0].stand: "bech" is not the name of a stand; name one of '
     '"bench"'),
    (WORLD.split(b"[goal]")[0] + b"[goal]\n",
     "w.toml:15: goal: the goal asks for nothing; give it [[goal.reach]], [[goal.hold]], "
     "[goal.end], [[goal.avoid]] or a deadline"),
    (WORLD.replace(b"tolerance = 5", b"tolerance = 200"),
     "w.toml:29: goal.end.tolerance: 200 is outside 0..180; write one within it"),
    (WORLD.replace(b"deadline = 30", b"deadline = 0"),
     "w.toml:16: goal.deadline: 0 is outside 0.1..86400; write one within it"),
    (WORLD.replace(b"[goal.end]", b"[goal.end]\nspeed = 3"),
     "w.toml:27: goal.end.speed: unknown key; expected one of name, points, heading, "
     "tolerance"),
])
def test_a_bad_goal_says_where_and_what(text: bytes, expected: str) -> None:
    with pytest.raises(WorldError) as refused:
        decode_world(text, "w.toml")
    assert str(refused.value).startswith(expected), str(refused.value)


def _ranged() -> list[tuple[str, float, float]]:
    found = []
    for prefix, schema in (("goal", GoalTable), ("goal.reach", GoalRegionTable),
                           ("goal.hold", HoldTable)):
        info = mi.type_info(schema)
        assert isinstance(info, mi.StructType)
        for field in info.fields:
            kind = field.type.type if isinstance(field.type, mi.Metadata) else field.type
            if isinstance(kind, mi.FloatType) and field.name != "heading":
                assert kind.ge is not None and kind.le is not None, field.name
                found.append((f"{prefix}.{field.encode_name}", kind.ge, kind.le))
    return found


def test_the_spec_gives_each_quantity_of_the_goal_its_range() -> None:
    spec = (ROOT / "spec" / "simulator.md").read_text()
    ranged = _ranged()
    assert {name for name, _, _ in ranged} == {"goal.deadline", "goal.reach.tolerance",
                                               "goal.hold.within", "goal.hold.seconds"}
    for name, low, high in ranged:
        row = next((line for line in spec.splitlines() if line.startswith(f"| {name} |")), None)
        assert row is not None, name
        assert f"| {low:g}..{high:g} |" in row, (row, low, high)


# rl1c sim ---------------------------------------------------------------------------------


def test_rl1c_sim_reports_a_missed_goal_in_json_and_exits_20(tmp_path: Path) -> None:
    world, program = tmp_path / "w.toml", tmp_path / "p.rob"
    world.write_bytes(WORLD)
    program.write_text("(MVI 6,6,440)\n(END)\n")
    picture = tmp_path / "p.svg"
    result = rl1c("sim", program, "--world", world, "--format", "json", "--svg", picture)
    assert result.exit_code == GOAL_MISSED == 20, result.output
    drawn = picture.read_text()  # the hold and the pit in red, each crossed where missed
    assert drawn.count('<g class="goal" stroke="#d11"') == 2
    assert drawn.count('<g class="goal" stroke="#2a9d2a"') == 2  # the gate, the end
    assert drawn.count('class="goal-miss"') == 2
    report = json.loads(result.stdout)
    start = float(report["trace"][0]["time"])  # the MVI's: what statements before it cost

    def t(seconds: float) -> float:
        return round(start + seconds, 4)

    ended = t(440 / SPEED)
    assert report["goal"] == {"met": False, "parts": [
        {"part": "reach", "name": "gate", "met": True, "time": t(8.0),
         "pose": [300.0, 150.0, 0.0],
         "text": f"reached at {start + 8:.2f} s at (300.0, 150.0) heading 0.0"},
        {"part": "hold", "name": "bench", "met": False, "time": ended,
         "pose": [500.0, 150.0, 0.0],
         "text": "never stood still 0.5 s with the camera within 40 cm of its marker: the "
                 f"nearest stop was 183.8 cm from it, from {ended:.2f} s at (500.0, 150.0) "
                 "heading 0.0"},
        {"part": "end", "name": "end", "met": True, "time": ended,
         "pose": [500.0, 150.0, 0.0],
         "text": f"ended at {ended:.2f} s at (500.0, 150.0) heading 0.0"},
        {"part": "avoid", "name": "pit", "met": False, "time": t(340 / SPEED),
         "pose": [400.0, 150.0, 0.0],
         "text": f"entered at {start + 340 / SPEED:.2f} s at (400.0, 150.0) heading 0.0"},
        {"part": "deadline", "name": "30 s", "met": True, "time": ended,
         "pose": [500.0, 150.0, 0.0],
         "text": f"the run ended at {ended:.2f} s, within the deadline of 30 s"},
    ]}
    assert report["status"] == {
        "code": "goal-missed", "exit_status": 20, "line": None,
        "message": 'the program ended, but goal missed (2 of 5 parts): hold at stand '
                   '"bench"; avoid "pit"'}


def test_rl1c_sim_says_goal_met_and_exits_0_and_marks_the_regions(tmp_path: Path) -> None:
    world, program, picture = tmp_path / "w.toml", tmp_path / "p.rob", tmp_path / "p.svg"
    world.write_bytes(WORLD.split(b"[[goal.hold]]")[0])  # the deadline and the gate
    program.write_text("(MVI 6,6,300)\n(END)\n")
    result = rl1c("sim", program, "--world", world, "--svg", picture)
    assert result.exit_code == 0, result.output
    assert '\ngoal met\n- reach "gate": met, reached at 8.00 s' in result.stdout
    drawn = picture.read_text()
    assert drawn.count('<g class="goal" stroke="#2a9d2a"') == 1  # the gate, met
    assert "p.rob on w.toml: goal met" in drawn


def test_a_fault_keeps_its_status_and_the_goal_is_judged_beside_it(tmp_path: Path) -> None:
    world, program = tmp_path / "w.toml", tmp_path / "p.rob"
    world.write_bytes(WORLD)
    program.write_text("(MOV 12,12)\n:10 (TIM 10)\n#10\n")  # off the floor at x = 760
    result = rl1c("sim", program, "--world", world, "--format", "json")
    assert result.exit_code == 13, result.output
    report = json.loads(result.stdout)
    assert report["status"]["code"] == "device-error"
    assert report["goal"]["met"] is False
    assert [part["met"] for part in report["goal"]["parts"]] == [True, False, False, False,
                                                                 True]
    text = rl1c("sim", program, "--world", world).stdout
    assert "goal missed (3 of 5 parts)" in text


def test_a_world_without_a_goal_reports_none(tmp_path: Path) -> None:
    world, program = tmp_path / "w.toml", tmp_path / "p.rob"
    world.write_bytes(WORLD.split(b"[goal]")[0])
    program.write_text("(MVI 6,6,100)\n(END)\n")
    result = rl1c("sim", program, "--world", world, "--format", "json")
    assert result.exit_code == 0 and json.loads(result.stdout)["goal"] is None
    assert "goal" not in rl1c("sim", program, "--world", world).stdout


@pytest.mark.parametrize("name", ["sample.world.toml", "sample.mirrored.world.toml"])
def test_the_sample_worlds_state_listing_1s_goal_and_it_is_met(name: str) -> None:
    result = rl1c("sim", ROOT / "examples" / "sample.rob", "--world", ROOT / "examples" / name)
    assert result.exit_code == 0, result.output
    assert "\ngoal met\n" in result.stdout
    assert '- hold at stand "stand": met, stood still 0.5 s' in result.stdout
