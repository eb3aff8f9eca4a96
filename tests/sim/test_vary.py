"""The world file's [vary] table (vm/sim/vary.py, spec/simulator.md "Varying the world"):
each run's draws are a function of its seed alone, stay within their bounds and their
parameter's range, have the closed forms' means and variances, and a table that is wrong
is refused with its key path and line."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from statistics import NormalDist, fmean, pvariance

import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from support.cli import rl1c
from support.hold import WAIT

from rl1.vm.sim.vary import Normal, Uniform, uniform_draw
from rl1.vm.sim.world import World, WorldError, decode_world

WORLD = """\
[floor]
size = [600, 400]
[start]
x = 100.0
y = 200.0
[vehicle]
k1 = 0.02
[[stands]]
name = "bench"
x = 400.0
y = 330.0
facing = -90.0
[goal]
[[goal.hold]]
stand = "bench"
"""
VARY_LINE = WORLD.count("\n") + 2  # the line after [vary]

VARIED = WORLD + """\
[vary]
start.x = { normal = [0, 5], within = [-10, 10] }
start.heading = { uniform = [-3, 3] }
stands.bench.x = { normal = [2, 4] }
stands.bench.facing = { uniform = [-10, 10] }
vehicle.k1 = { uniform = [-0.005, 0.005] }
noise.image_px = { uniform = [0, 1] }
"""


def world(text: str = VARIED) -> World:
    return decode_world(text.encode(), "w.toml")


# Determinism ----------------------------------------------------------------------------


@given(st.integers(0, 2**32 - 1))
def test_the_same_seed_draws_the_same_world(seed: int) -> None:
    assert world().drawn(seed) == world().drawn(seed)


def test_each_key_draws_alone_so_adding_or_reordering_keys_leaves_the_others() -> None:
    reordered = WORLD + """\
[vary]
noise.image_px = { uniform = [0, 1] }
vehicle.k1 = { uniform = [-0.005, 0.005] }
start.x = { normal = [0, 5], within = [-10, 10] }
"""
    for seed in range(20):
        everything = world().drawn(seed)[1]
        some = world(reordered).drawn(seed)[1]
        assert {key: everything[key] for key in some} == some


def test_seeds_draw_different_worlds() -> None:
    drawn = {world().drawn(seed)[1]["start.x"] for seed in range(50)}
    assert len(drawn) == 50


def test_a_world_without_vary_is_the_world_as_written() -> None:
    plain = world(WORLD)
    assert plain.drawn(7) == (plain, {})


def test_a_drawn_world_moves_what_its_values_say() -> None:
    varied, values = world().drawn(3)
    written = world(WORLD)
    assert varied.start == (values["start.x"], written.start[1], values["start.heading"])
    stand = varied.stands[0]
    assert (stand.x, stand.facing) == (values["stands.bench.x"], values["stands.bench.facing"])
    assert varied.vehicle.k1 == values["vehicle.k1"]
    assert varied.noise.image_px == values["noise.image_px"]
    assert varied.noise.slip == 0  # noise off but what is drawn
    # The goal's hold is at the marker of the stand where it is in this run.
    assert varied.goal is not None
    assert varied.goal.holds[0].marker == stand.marker() != written.stands[0].marker()


# Bounds --------------------------------------------------------------------------------

finite = st.floats(-1e3, 1e3, allow_nan=False)


@given(st.tuples(finite, finite).map(sorted), st.floats(0, 1, exclude_max=True))
def test_a_uniform_draw_lies_within_its_bounds(bounds: list[float], u: float) -> None:
    low, high = bounds
    assert low <= Uniform(low, high).draw(u, -math.inf, math.inf) <= high


@given(finite, st.floats(1e-3, 1e3), st.tuples(finite, finite).map(sorted),
       st.tuples(finite, finite).map(sorted), st.floats(0, 1, exclude_max=True))
def test_a_normal_draw_lies_within_its_bounds_and_its_parameter_s_range(
        mean: float, sd: float, within: list[float], allowed: list[float], u: float) -> None:
    normal = Normal(mean, sd, (within[0], within[1]))
    low, high = normal.bounds(*allowed)
    if low > high:
        return  # no room: such a table is refused (below)
    assert low <= normal.draw(u, *allowed) <= high


@given(st.integers(0, 2**32 - 1))
def test_every_run_s_values_lie_within_the_table_s_bounds(seed: int) -> None:
    values = world().drawn(seed)[1]
    assert 90 <= values["start.x"] <= 110
    assert -3 <= values["start.heading"] <= 3
    assert 0.015 <= values["vehicle.k1"] <= 0.025
    assert -100 <= values["stands.bench.facing"] <= -80
    assert 0 <= values["noise.image_px"] <= 1


def test_a_normal_without_bounds_stays_within_its_parameter_s_range() -> None:
    # The start's y is on the floor (0..400) whatever the draw: a normal of sd 300 from
    # y = 200 is cut there.
    text = WORLD + "[vary]\nstart.y = { normal = [0, 300] }\n"
    ys = [world(text).drawn(seed)[1]["start.y"] for seed in range(2000)]
    assert min(ys) >= 0 and max(ys) <= 400
    assert min(ys) < 20 and max(ys) > 380  # it does reach near both edges


# Means and variances --------------------------------------------------------------------

DRAWS = 20_000


def _offsets(dist: Uniform | Normal, low: float = -math.inf, high: float = math.inf
             ) -> list[float]:
    return [dist.draw(uniform_draw(seed, "start.x"), low, high) for seed in range(DRAWS)]


def _truncated_normal(mean: float, sd: float, low: float, high: float) -> tuple[float, float]:
    """The mean and variance of a normal truncated to low..high (Johnson, Kotz and
    Balakrishnan, Continuous Univariate Distributions, vol. 1, 10.1)."""
    unit = NormalDist()
    a, b = (low - mean) / sd, (high - mean) / sd
    mass = unit.cdf(b) - unit.cdf(a)
    pa, pb = unit.pdf(a), unit.pdf(b)
    shift = (pa - pb) / mass
    return (mean + sd * shift,
            sd * sd * (1 + ((a * pa if math.isfinite(a) else 0) - (b * pb if math.isfinite(b)
                                                                  else 0)) / mass - shift ** 2))


def _assert_moments(draws: list[float], mean: float, variance: float) -> None:
    # Tolerances of 5 standard errors, for a statistic computed once with fixed seeds:
    # the mean's is sd / sqrt(n), the variance's at most variance * sqrt(2 / n) for
    # these distributions (whose kurtosis is at most a normal's).
    n = len(draws)
    assert fmean(draws) == pytest.approx(mean, abs=5 * math.sqrt(variance / n))
    assert pvariance(draws) == pytest.approx(variance, abs=5 * variance * math.sqrt(2 / n))


def test_uniform_draws_have_the_closed_form_s_mean_and_variance() -> None:
    _assert_moments(_offsets(Uniform(-3, 7)), 2.0, 10 ** 2 / 12)


@pytest.mark.parametrize(("mean", "sd", "within"), [
    (0.0, 5.0, None),  # untruncated
    (0.0, 5.0, (-5.0, 5.0)),  # at one sd either side
    (1.0, 2.0, (0.0, 10.0)),  # cut on one side
    (0.0, 1.0, (2.0, 4.0)),  # in the upper tail only: the mirrored path
    (0.0, 1.0, (-4.0, -2.0)),  # in the lower tail only
])
def test_normal_draws_have_the_truncated_closed_form_s_mean_and_variance(
        mean: float, sd: float, within: tuple[float, float] | None) -> None:
    low, high = within or (-math.inf, math.inf)
    expected = _truncated_normal(mean, sd, low, high)
    _assert_moments(_offsets(Normal(mean, sd, within), -1e6, 1e6), *expected)


# Refusals -------------------------------------------------------------------------------


@pytest.mark.parametrize(("table", "says"), [
    ("start.x = { uniform = [5, 1] }",
     r"w\.toml:{line}: vary\.start\.x\.uniform: \[5, 1\] runs backwards"),
    ("start.x = { uniform = [0, 1], within = [0, 1] }",
     r"w\.toml:{line}: vary\.start\.x\.within: bounds a normal"),
    ("start.x = { normal = [0, 1], uniform = [0, 1] }",
     r"w\.toml:{line}: vary\.start\.x\.normal: and uniform both given"),
    ("start.x = {}", r"w\.toml:{line}: vary\.start\.x: gives no distribution; write"),
    ("start.x = { normal = [0, 0] }",
     r"w\.toml:{line}: vary\.start\.x\.normal\[1\]: 0 is outside \(more than 0\)"),
    ("start.x = { normal = [0, 1], within = [3, -3] }",
     r"w\.toml:{line}: vary\.start\.x\.within: \[3, -3\] runs backwards"),
    ("start.x = { uniform = [0, nan] }",
     r"w\.toml:{line}: vary\.start\.x\.uniform\[1\]: nan is not a finite number"),
    ("start.x = { uniform = [-200, 0] }",
     r"w\.toml:{line}: vary\.start\.x: offsets -200\.\.0 would leave the value's range; "
     r"offsets within -100\.\.500 keep it"),
    ("start.x = { normal = [100, 1], within = [-5, 5] }",
     r"w\.toml:{line}: vary\.start\.x: the normal \[100, 1\] has less than one draw in a "
     "million"),
    ("start.z = { uniform = [0, 1] }",
     r"w\.toml:{line}: vary\.start\.z: unknown key; expected one of x, y, heading"),
    ("stands.bnch.x = { uniform = [0, 1] }",
     r'w\.toml:{line}: vary\.stands\.bnch\.x: no stand is named "bnch"; name one of "bench"'),
    ("vehicle.rotate_speed = { uniform = [0, 1] }",
     r"w\.toml:{line}: vary\.vehicle\.rotate_speed: a whole number, which is never drawn"),
    ("vehicle.tred = { uniform = [0, 1] }",
     r"w\.toml:{line}: vary\.vehicle\.tred: unknown key; did you mean tread\? \(expected one "
     r"of length, width, "
     "tread,"),
    ("noise.odometry = { uniform = [0, 0.5] }",
     r"w\.toml:{line}: vary\.noise\.odometry: offsets 0\.\.0\.5 would leave the value's "
     r"range; offsets within 0\.\.0\.1 keep it"),
    ("vehicle.trace_interval = { uniform = [-0.0499, 0] }",
     r"w\.toml:{line}: vary\.vehicle\.trace_interval: offsets -0\.0499\.\.0 would leave"),
    ("colour = 3", r"w\.toml:{line}: vary\.colour: unknown key; expected one of start, "
     "stands, vehicle, noise"),
])
def test_a_wrong_vary_table_is_refused_with_its_key_path_and_line(table: str,
                                                                  says: str) -> None:
    text = WORLD + "[limits]\ntime = 86400\n[vary]\n" + table + "\n"
    with pytest.raises(WorldError, match=says.format(line=VARY_LINE + 2)):
        world(text)


def test_a_table_written_as_tables_reads_as_dotted_keys() -> None:
    tables = WORLD + """\
[vary.start.x]
normal = [0, 5]
within = [-10, 10]
[vary.stands.bench]
x = { normal = [2, 4] }
"""
    dotted = WORLD + """\
[vary]
start.x = { normal = [0, 5], within = [-10, 10] }
stands.bench.x = { normal = [2, 4] }
"""
    assert world(tables).drawn(11) == world(dotted).drawn(11)


def test_of_two_stands_of_one_name_the_last_is_drawn_and_both_are_kept() -> None:
    # The goal holds at the last stand of a name (the world's markers by name): that is
    # the one a key of that name moves.
    text = WORLD.replace("[goal]", '[[stands]]\nname = "bench"\nx = 800.0\ny = 100.0\n'
                                   "facing = 90.0\n[goal]")
    varied = world(text + "[vary]\nstands.bench.x = { uniform = [5, 5] }\n").drawn(0)[0]
    assert [(stand.x, stand.y) for stand in varied.stands] == [(400.0, 330.0), (805.0, 100.0)]
    assert varied.goal is not None
    assert varied.goal.holds[0].marker == varied.stands[1].marker()


# The command line -----------------------------------------------------------------------

def test_a_campaign_s_line_records_the_values_its_seed_s_run_draws(tmp_path: Path) -> None:
    program, world_file, out = tmp_path / "w.rob", tmp_path / "w.toml", tmp_path / "r.jsonl"
    program.write_text(WAIT)
    world_file.write_text(VARIED)
    result = rl1c("sim", program, "--world", world_file, "--runs", "3", "--seed", "5",
                  "--jobs", "1", "--out", out)
    assert result.exit_code == 0, result.output
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    assert [line["varied"] for line in lines] == [world().drawn(seed)[1]
                                                 for seed in (5, 6, 7)]
    # The replay command's run draws the same world, and says so.
    single = rl1c("sim", program, "--world", world_file, "--seed", "6", "--format", "json")
    said = dict(re.findall(r"(\S+) = (\S+?)(?:,|$)", single.stderr.split("seed 6: ", 1)[1]))
    assert {key: float(value) for key, value in said.items()} == pytest.approx(
        lines[1]["varied"], rel=1e-5)
    assert json.loads(single.stdout)["track"][0][1:3] == pytest.approx(
        [lines[1]["varied"]["start.x"], 200.0], abs=0.01)


def test_a_run_without_a_seed_is_the_world_as_written(tmp_path: Path) -> None:
    program, world_file = tmp_path / "w.rob", tmp_path / "w.toml"
    program.write_text(WAIT)
    world_file.write_text(VARIED)
    result = rl1c("sim", program, "--world", world_file, "--format", "json")
    assert "note" not in result.stderr
    assert json.loads(result.stdout)["track"][0][1:3] == [100.0, 200.0]


# Any table ------------------------------------------------------------------------------

KEYS = ["start.x", "start.y", "start.heading", "stands.bench.x", "stands.bench.facing",
        "stands.desk.y", "vehicle.k1", "vehicle.tread", "vehicle.trace_interval",
        "vehicle.rotate_speed", "vehicle.nope", "noise.slip", "noise.odometry",
        "noise.ultrasonic_dropout", "start.z"]
wild = st.one_of(st.floats(-2e6, 2e6), st.integers(-10, 10), st.sampled_from(
    [0.0, 1e-300, -1e-300, math.inf, -math.inf, math.nan]))
small = st.floats(-50, 50)
bounds = st.tuples(small, small).map(lambda pair: (min(pair), max(pair)))
entry = st.one_of(  # mostly tables that may hold, then anything
    st.fixed_dictionaries({"uniform": bounds}),
    st.fixed_dictionaries({"normal": st.tuples(small, st.floats(1e-3, 50))},
                          optional={"within": bounds}),
    st.fixed_dictionaries({}, optional={key: st.tuples(wild, wild)
                                        for key in ("uniform", "normal", "within")}))


def _toml(value: object) -> str:
    match value:
        case float() if math.isnan(value):
            return "nan"
        case float() if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        case tuple():
            return "[" + ", ".join(map(_toml, value)) + "]"
    return repr(value)


@given(st.dictionaries(st.sampled_from(KEYS), entry, max_size=5), st.integers(0, 2**32 - 1))
# Found by it: a draw at its range's end (0 of 0..10, written in integers) took the
# range's int, and the setting was then refused as a whole number.
@example({"noise.slip": {"uniform": (0.0, 0.0)}}, 0)
def test_any_vary_table_is_refused_with_its_place_or_draws_values_in_range(
        table: dict[str, dict[str, tuple[object, object]]], seed: int) -> None:
    text = WORLD + "[vary]\n" + "".join(
        f"{key} = {{ " + ", ".join(f"{name} = {_toml(value)}" for name, value in
                                   spread.items()) + " }\n"
        for key, spread in table.items())
    try:
        varied = world(text)
    except WorldError as error:
        assert re.match(r"w\.toml:\d+: vary\.", str(error)), str(error)
        return
    drawn, values = varied.drawn(seed)
    assert set(values) == set(table)
    for key, value in values.items():
        parameter = varied.parameter(key)
        assert parameter.low <= value <= parameter.high
        assert drawn.parameter(key).value == value
