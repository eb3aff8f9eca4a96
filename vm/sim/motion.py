"""The vehicle's kinematics and odometry (spec/simulator.md, "Motion").

Two drive wheels on a steered drive unit: the unit travels at the mean of the wheel
speeds in the direction `heading + steering`, and turns (body and unit together) at
(right - left) / tread. Between two changes of wheel speed the path is an exact arc, so
where the vehicle ends does not depend on the step the simulator takes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


def heading_degrees(radians: float, digits: int | None = None) -> float:
    """A heading as the reports and the goal give it: degrees in (-180, 180], rounded to
    `digits` when given (rounded first, so that 180.004 reads 180.0, not -180.0)."""
    degrees = math.degrees(radians) if digits is None else round(math.degrees(radians), digits)
    degrees %= 360.0
    if degrees <= 180.0:
        return degrees
    return degrees - 360.0 if digits is None else round(degrees - 360.0, digits)


@dataclass(frozen=True, slots=True)
class Pose:
    x: float  # cm
    y: float  # cm
    heading: float  # radians, counterclockwise from +x


@dataclass(slots=True)
class Odometer:
    """The distance counters: each wheel's and the centre's signed travel, in cm."""

    right: float = 0.0
    left: float = 0.0
    centre: float = 0.0


def advance(pose: Pose, steering: float, left: float, right: float, tread: float,
            seconds: float) -> Pose:
    """Where the vehicle is after `seconds` at wheel speeds `left`, `right` (cm/s) with
    the drive unit steered `steering` radians (+ left) from the heading."""
    speed = (left + right) / 2
    turn = (right - left) / tread
    direction = pose.heading + steering
    if abs(turn * seconds) < 1e-12:
        return Pose(pose.x + speed * seconds * math.cos(direction),
                    pose.y + speed * seconds * math.sin(direction), pose.heading)
    radius = speed / turn
    swept = turn * seconds
    return Pose(pose.x + radius * (math.sin(direction + swept) - math.sin(direction)),
                pose.y - radius * (math.cos(direction + swept) - math.cos(direction)),
                pose.heading + swept)


def count(odometer: Odometer, left: float, right: float, seconds: float) -> None:
    """Add what the wheels turned in `seconds` to the counters."""
    odometer.left += left * seconds
    odometer.right += right * seconds
    odometer.centre += (left + right) / 2 * seconds


def time_to_cover(distance: float, left: float, right: float) -> float:
    """Seconds for the centre to cover `distance` cm (its counter's absolute change) at
    wheel speeds `left`, `right` cm/s; infinite when the centre does not move."""
    speed = abs(left + right) / 2
    return math.inf if speed == 0 else abs(distance) / speed
