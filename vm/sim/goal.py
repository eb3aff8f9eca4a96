"""What success is (spec/simulator.md, "The goal"): the world's `[goal]`, and its
judgement of a run from the run's record, the exact motion of each step of the
simulator, never the decimated track: a region crossed between two kept points of the
track still counts.

The record is a sequence of `Step`s (the pose before and after each step of the
simulator, with their times) and the time the run ended; between two steps, and after
the last, the vehicle stood still. `Judge` makes the judgement online, one step at a
time, through the simulator's `on_move` hook, so that a run of millions of steps keeps
nothing of them; `judge` gives it a whole record. `World.judge` makes the judge of a
world's goal (this module knows nothing of worlds, which hold goals).

A region is judged by the vehicle's centre, the pose's point: within a step the centre
is taken along the chord from one pose to the next, and the heading to turn evenly
between them (a step lasts at most 0.05 s, 3 cm at full speed: the chord and the arc
differ by well under a millimetre, and a straight run is exact).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import Any, Literal, NamedTuple

from .geometry import Box, Point, bounding_box, boxes_overlap, inside, segment_nearest
from .motion import Pose, heading_degrees

GOAL_MISSED = 20
"""The exit status of `rl1c sim` when the program ended but the world's goal was missed
(10-13 are the faults', which come first: spec/language.md, section 10)."""

Part = Literal["reach", "hold", "end", "avoid", "deadline"]


@dataclass(frozen=True, slots=True)
class Region:
    """A polygon of the goal, and, when `heading` is not None, the heading (radians) the
    vehicle must have there, within `tolerance` (radians)."""

    name: str
    points: tuple[Point, ...]
    heading: float | None = None
    tolerance: float = 0.0


@dataclass(frozen=True, slots=True)
class Hold:
    """The vehicle stands still for `seconds` or more with its camera (`camera_ahead` cm
    ahead of its centre) within `within` cm of the marker of stand `stand`, at
    `marker`."""

    stand: str
    marker: Point
    within: float
    seconds: float


@dataclass(frozen=True, slots=True)
class Goal:
    """What a run must achieve: reach each of `reach`, be held at each of `holds`, end
    in `end`, never enter any of `avoid`; and when `deadline` is not None, have met the
    reaches and holds and ended by then (s of simulated time)."""

    reach: tuple[Region, ...] = ()
    holds: tuple[Hold, ...] = ()
    end: Region | None = None
    avoid: tuple[Region, ...] = ()
    deadline: float | None = None


class Step(NamedTuple):
    """One step of the simulator: the vehicle went from `before` at time `start` to
    `after` at time `end`, its wheels turning at constant speeds."""

    start: float
    end: float
    before: Pose
    after: Pose


# The verdict ------------------------------------------------------------------------------


def _at(time: float, pose: Pose) -> str:
    heading = heading_degrees(pose.heading)
    return f"{time:.2f} s at ({pose.x:.1f}, {pose.y:.1f}) heading {heading:.1f}"


@dataclass(frozen=True, slots=True)
class Outcome:
    """How one part of the goal went: met or not, what happened (`text`), and when and
    where that was (None when it never happened)."""

    part: Part
    name: str
    met: bool
    text: str
    time: float | None = None
    pose: Pose | None = None

    def title(self) -> str:
        match self.part:
            case "hold":
                return f'hold at stand "{self.name}"'
            case "deadline":
                return "deadline"
            case _:
                return f'{self.part} "{self.name}"'

    def to_json(self) -> dict[str, Any]:
        return {"part": self.part, "name": self.name, "met": self.met, "text": self.text,
                "time": None if self.time is None else round(self.time, 4),
                "pose": None if self.pose is None else [
                    round(self.pose.x, 2), round(self.pose.y, 2),
                    round(heading_degrees(self.pose.heading), 2)]}


@dataclass(frozen=True, slots=True)
class Verdict:
    """The goal's judgement of a run: one outcome per part, in the goal's order (reach,
    hold, end, avoid, deadline)."""

    outcomes: tuple[Outcome, ...]

    @property
    def met(self) -> bool:
        return all(outcome.met for outcome in self.outcomes)

    def missed(self) -> list[Outcome]:
        return [outcome for outcome in self.outcomes if not outcome.met]

    def headline(self) -> str:
        """`goal met`, or which parts were missed."""
        if self.met:
            return "goal met"
        missed = self.missed()
        return (f"goal missed ({len(missed)} of {len(self.outcomes)} "
                f"part{'s' if len(self.outcomes) != 1 else ''}): "
                + "; ".join(outcome.title() for outcome in missed))

    def to_json(self) -> dict[str, Any]:
        return {"met": self.met, "parts": [outcome.to_json() for outcome in self.outcomes]}


# Geometry of a step ----------------------------------------------------------------------

Span = tuple[float, float]  # a closed interval of a step's fraction, 0..1


def _crossings(a: Point, b: Point, polygon: Sequence[Point]) -> list[float]:
    """The fractions of segment ab where it crosses the polygon's edges."""
    found = []
    dx, dy = b[0] - a[0], b[1] - a[1]
    for i in range(len(polygon)):
        (px, py), (qx, qy) = polygon[i], polygon[(i + 1) % len(polygon)]
        ex, ey = qx - px, qy - py
        denominator = dx * ey - dy * ex
        if denominator == 0:
            continue  # parallel: the ends of the neighbouring edges cross instead
        s = ((px - a[0]) * ey - (py - a[1]) * ex) / denominator
        u = ((px - a[0]) * dy - (py - a[1]) * dx) / denominator
        if 0 <= s <= 1 and 0 <= u <= 1:
            found.append(s)
    return found


def _inside_spans(a: Point, b: Point, polygon: Sequence[Point]) -> list[Span]:
    """Where along segment ab the point lies inside the polygon (even-odd rule)."""
    cuts = sorted({0.0, 1.0, *_crossings(a, b, polygon)})
    spans: list[Span] = []
    for low, high in pairwise(cuts):
        middle = (low + high) / 2
        if inside(a[0] + middle * (b[0] - a[0]), a[1] + middle * (b[1] - a[1]), polygon):
            if spans and spans[-1][1] == low:
                spans[-1] = (spans[-1][0], high)
            else:
                spans.append((low, high))
    if not spans and a == b and inside(*a, polygon):
        spans.append((0.0, 1.0))  # a turn in place, inside
    return spans


def _heading_spans(start: float, turn: float, region: Region) -> list[Span]:
    """Where along a step turning evenly from `start` by `turn` radians the heading is
    within the region's tolerance of its heading."""
    if region.heading is None:
        return [(0.0, 1.0)]
    if turn == 0:
        return [(0.0, 1.0)] if _heading_off(start, region) <= region.tolerance else []
    low, high = sorted((start, start + turn))
    spans = []
    first = math.floor((low - region.heading - region.tolerance) / math.tau)
    last = math.ceil((high - region.heading + region.tolerance) / math.tau)
    for k in range(first, last + 1):
        centre = region.heading + k * math.tau
        ends = sorted(((centre - region.tolerance - start) / turn,
                       (centre + region.tolerance - start) / turn))
        if ends[1] >= 0 and ends[0] <= 1:
            spans.append((max(0.0, ends[0]), min(1.0, ends[1])))
    return sorted(spans)


def _first(spans: list[Span], others: list[Span]) -> float | None:
    """The least fraction in both sets of spans."""
    best = None
    for low, high in spans:
        for other_low, other_high in others:
            start = max(low, other_low)
            if start <= min(high, other_high) and (best is None or start < best):
                best = start
    return best


def _distance(point: Point, polygon: Sequence[Point]) -> float:
    """How far `point` lies from the polygon: 0 inside it."""
    if inside(*point, polygon):
        return 0.0
    return min(segment_nearest(*point, polygon[i], polygon[(i + 1) % len(polygon)])[2]
               for i in range(len(polygon)))


def _heading_off(heading: float, region: Region) -> float:
    """How far (radians) `heading` lies from the region's heading."""
    return 0.0 if region.heading is None else abs(math.remainder(heading - region.heading,
                                                                  math.tau))


def _along(step: Step, fraction: float) -> tuple[float, Pose]:
    start, end, before, after = step
    return (start + fraction * (end - start),
            Pose(before.x + fraction * (after.x - before.x),
                 before.y + fraction * (after.y - before.y),
                 before.heading + fraction * (after.heading - before.heading)))


def _entry(step: Step, region: Region) -> tuple[float, Pose] | None:
    """When and where in `step` the vehicle first was in `region` (its heading within
    the tolerance, when the region gives one), or None."""
    a, b = (step.before.x, step.before.y), (step.after.x, step.after.y)
    fraction = _first(_inside_spans(a, b, region.points),
                      _heading_spans(step.before.heading,
                                     step.after.heading - step.before.heading, region))
    return None if fraction is None else _along(step, fraction)


# The judgement ---------------------------------------------------------------------------


def _box_distance(x: float, y: float, box: Box) -> float:
    """How far (x, y) lies from `box`: never more than from what the box holds."""
    return math.hypot(max(box[0] - x, 0.0, x - box[2]), max(box[1] - y, 0.0, y - box[3]))


@dataclass(slots=True)
class _Reaching:
    region: Region
    box: Box
    reached: tuple[float, Pose] | None = None  # when the part was met
    entered: tuple[float, Pose] | None = None  # when the centre first entered, any heading
    nearest: tuple[float, float, Pose] | None = None  # distance, time, pose


@dataclass(slots=True)
class _Holding:
    hold: Hold
    held: tuple[float, Pose] | None = None  # when it had stood there `seconds`
    nearest: tuple[float, float, Pose] | None = None  # of the long enough stops


class Judge:
    """`goal` judged online from `start` (the simulator's first pose) for a vehicle whose
    camera is `camera_ahead` cm ahead of its centre (World.judge makes one from a world):
    `step` for each step of the simulator (its `on_move` hook), then `verdict` with the
    time the run ended."""

    def __init__(self, goal: Goal, start: Pose, camera_ahead: float) -> None:
        self.goal = goal
        self.pose = start
        self.camera_ahead = camera_ahead
        self.stood_since = 0.0  # when the last step ended: the vehicle stands since
        # The regions' boxes spare a step the polygons it cannot touch (a world may give
        # them 10,000 points), and the nearest approach the distances that cannot win.
        self.reaching = [_Reaching(region, bounding_box(region.points))
                         for region in self.goal.reach]
        self.holding = [_Holding(hold) for hold in self.goal.holds]
        self.avoid = [(region, bounding_box(region.points)) for region in self.goal.avoid]
        self.entered: list[tuple[float, Pose] | None] = [None] * len(self.goal.avoid)
        self._visit(Step(0.0, 0.0, self.pose, self.pose))  # where it starts counts

    def step(self, start: float, end: float, before: Pose, after: Pose) -> None:
        """The vehicle went from `before` at `start` to `after` at `end`."""
        if start > self.stood_since:
            self._stood(self.stood_since, start)
        self._visit(Step(start, end, before, after))
        self.pose = after
        self.stood_since = end

    def verdict(self, ended: float) -> Verdict:
        """The verdict of a run that ended at `ended` (s) where the last step left the
        vehicle: it rests there from then on, which counts as standing still."""
        self._stood(self.stood_since, math.inf)
        goal = self.goal
        outcomes = [*(self._reached(reaching) for reaching in self.reaching),
                    *(self._held(holding) for holding in self.holding)]
        if goal.end is not None:
            outcomes.append(self._ended(goal.end, ended))
        outcomes += [self._avoided(region, entered)
                     for region, entered in zip(goal.avoid, self.entered, strict=True)]
        if goal.deadline is not None:
            outcomes.append(Outcome(
                "deadline", f"{goal.deadline:g} s", ended <= goal.deadline,
                f"the run ended at {ended:.2f} s, "
                + ("within" if ended <= goal.deadline else "after")
                + f" the deadline of {goal.deadline:g} s", ended, self.pose))
        return Verdict(tuple(outcomes))

    # What each step and each stop does

    def _visit(self, step: Step) -> None:
        before, after = step.before, step.after
        swept = bounding_box(((before.x, before.y), (after.x, after.y)))
        for reaching in self.reaching:
            if reaching.reached is not None:
                continue
            region = reaching.region
            if boxes_overlap(swept, reaching.box):
                reaching.reached = _entry(step, region)
                if reaching.entered is None:
                    reaching.entered = _entry(step, Region(region.name, region.points))
            if reaching.entered is None and (
                    reaching.nearest is None
                    or _box_distance(after.x, after.y, reaching.box) < reaching.nearest[0]):
                distance = _distance((after.x, after.y), region.points)
                if reaching.nearest is None or distance < reaching.nearest[0]:
                    reaching.nearest = (distance, step.end, after)
        for i, (region, box) in enumerate(self.avoid):
            if self.entered[i] is None and boxes_overlap(swept, box):
                self.entered[i] = _entry(step, region)

    def _stood(self, since: float, until: float) -> None:
        """The vehicle stood still at `self.pose` from `since` to `until`."""
        pose = self.pose
        camera = (pose.x + self.camera_ahead * math.cos(pose.heading),
                  pose.y + self.camera_ahead * math.sin(pose.heading))
        for holding in self.holding:
            hold = holding.hold
            if holding.held is not None or until - since < hold.seconds:
                continue
            distance = math.dist(camera, hold.marker)
            if distance <= hold.within:
                holding.held = (since + hold.seconds, pose)
            if holding.nearest is None or distance < holding.nearest[0]:
                holding.nearest = (distance, since, pose)

    # The outcomes

    def _lateness(self, time: float) -> str:
        """What an outcome at `time` adds when it is past the goal's deadline (and so is
        not met): ", after the deadline of D s"; empty when it is in time."""
        if self.goal.deadline is None or time <= self.goal.deadline:
            return ""
        return f", after the deadline of {self.goal.deadline:g} s"

    def _reached(self, reaching: _Reaching) -> Outcome:
        region = reaching.region
        if reaching.reached is not None:
            time, pose = reaching.reached
            lateness = self._lateness(time)
            return Outcome("reach", region.name, not lateness,
                           f"reached at {_at(time, pose)}{lateness}", time, pose)
        if reaching.entered is not None:
            time, pose = reaching.entered
            assert region.heading is not None  # entered, so the heading was never right
            return Outcome("reach", region.name, False, (
                f"entered at {_at(time, pose)}, but never with the heading within "
                f"{math.degrees(region.tolerance):g} degrees of "
                f"{heading_degrees(region.heading):g}"), time, pose)
        assert reaching.nearest is not None  # the start is a visit, outside the region
        distance, time, pose = reaching.nearest
        return Outcome("reach", region.name, False, f"never reached: the nearest the "
                       f"centre came was {distance:.1f} cm away, at {_at(time, pose)}",
                       time, pose)

    def _held(self, holding: _Holding) -> Outcome:
        hold = holding.hold
        what = f"{hold.seconds:g} s with the camera within {hold.within:g} cm of its marker"
        if holding.held is not None:
            time, pose = holding.held
            lateness = self._lateness(time)
            return Outcome("hold", hold.stand, not lateness,
                           f"stood still {what} by {_at(time, pose)}{lateness}", time, pose)
        assert holding.nearest is not None  # the rest after the run is long enough
        distance, time, pose = holding.nearest
        return Outcome("hold", hold.stand, False, f"never stood still {what}: the nearest "
                       f"stop was {distance:.1f} cm from it, from {_at(time, pose)}",
                       time, pose)

    def _ended(self, region: Region, ended: float) -> Outcome:
        pose = self.pose
        where = f"ended at {_at(ended, pose)}"
        distance = _distance((pose.x, pose.y), region.points)
        if distance > 0:
            return Outcome("end", region.name, False, f"{where}, {distance:.1f} cm outside "
                           "the region", ended, pose)
        if _heading_off(pose.heading, region) > region.tolerance:
            assert region.heading is not None
            return Outcome("end", region.name, False, (
                f"{where}: in the region, but the heading is more than "
                f"{math.degrees(region.tolerance):g} degrees from "
                f"{heading_degrees(region.heading):g}"), ended, pose)
        return Outcome("end", region.name, True, where, ended, pose)

    def _avoided(self, region: Region, entered: tuple[float, Pose] | None) -> Outcome:
        if entered is None:
            return Outcome("avoid", region.name, True, "never entered")
        time, pose = entered
        return Outcome("avoid", region.name, False, f"entered at {_at(time, pose)}",
                       time, pose)


def judge(judging: Judge, steps: Iterable[Step], ended: float) -> Verdict:
    """The verdict of `judging` on a run: the simulator's steps in order, and the time
    (s) the run ended."""
    for step in steps:
        judging.step(*step)
    return judging.verdict(ended)
