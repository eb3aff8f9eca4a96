"""The record of where the vehicle went, bounded whatever the run (spec/simulator.md,
"The record of a run"): the track the pictures and the JSON draw, decimated to a fixed
number of points per second of simulated time, and the recent poses the delayed sensors
look back on.

The simulator may take millions of steps (a short tracing interval, a long time limit);
neither record grows with them.
"""

from __future__ import annotations

from collections import deque

from .motion import Pose

POINTS_PER_SECOND = 20
"""Points of the track per second of simulated time, at most: the default step's rate,
finer than the pictures can show at the vehicle's speeds."""

MAX_TRACK_POINTS = 20_000
"""Points of the track in all (about 4 MB, and a 2 MB SVG): a longer run keeps every
other point, and half as many per second from then on, as often as it needs to."""

_ROUNDING = 1e-9  # s: steps of 0.05 s add up to times 0.04999... apart, which are kept

MAX_HISTORY = 2**16
"""Poses the sensor delay looks back on: thinned by halves past this, which only a delay
of more than 2**16 steps ever needs (a valid world's delay of at most 10 s holds about
10,000 at its shortest tracing interval)."""


class Track:
    """The poses of a run at times `spacing` s apart or more: the first (the start) and
    the last (where the vehicle is now) always, whatever was dropped between them."""

    def __init__(self, start: Pose) -> None:
        self.points: list[tuple[float, Pose]] = [(0.0, start)]
        self.spacing = 1 / POINTS_PER_SECOND  # s, at least, between two kept points

    def add(self, time: float, pose: Pose) -> None:
        """Record the pose at `time` (never before the last). The last point stands for
        the present: it is replaced until it lies `spacing` after the one before it."""
        points = self.points
        if len(points) >= 2 and points[-1][0] - points[-2][0] < self.spacing - _ROUNDING:
            points[-1] = (time, pose)
            return
        points.append((time, pose))
        if len(points) > MAX_TRACK_POINTS:
            del points[1:-1:2]  # keeps the first and the last, and every other between
            self.spacing *= 2


class History:
    """The poses of the last `delay` seconds of a run, and the one before them: enough
    to answer which pose was the last recorded at or before a time that only grows."""

    def __init__(self, start: Pose) -> None:
        self._poses: deque[tuple[float, Pose]] = deque([(0.0, start)])

    def add(self, time: float, pose: Pose) -> None:
        self._poses.append((time, pose))
        if len(self._poses) > MAX_HISTORY:
            last = self._poses[-1]
            self._poses = deque([*list(self._poses)[:-1:2], last])

    def at(self, time: float) -> Pose:
        """The last pose recorded at or before `time` (the start's before the run began);
        `time` must never be earlier than at the call before."""
        poses = self._poses
        while len(poses) >= 2 and poses[1][0] <= time:
            poses.popleft()
        return poses[0][1]
