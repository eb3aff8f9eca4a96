"""The ultrasonic range sensors A-D (spec/simulator.md, "Ultrasonic"): the nearest echo
in each sensor's cone from walls, obstacles and stands."""

from __future__ import annotations

import math
from collections.abc import Sequence

from .geometry import Point, ray_polygon
from .motion import Pose

# Where each sensor sits, as fractions of the body's half length and half width, and
# the way it looks (radians from the heading): A front, B right, C rear, D left.
SENSORS: dict[str, tuple[float, float, float]] = {
    "A": (1.0, 0.0, 0.0),
    "B": (0.0, -1.0, -math.pi / 2),
    "C": (-1.0, 0.0, math.pi),
    "D": (0.0, 1.0, math.pi / 2),
}
RAYS_PER_DEGREE = 1  # the cone is sampled by rays this many per degree


def sense(sensor: str, pose: Pose, length: float, width: float, cone_degrees: float,
          reach: float, obstacles: Sequence[Sequence[Point]]) -> float:
    """The distance in cm from `sensor` to the nearest surface in its cone, `reach`
    when there is none nearer."""
    along, across, facing = SENSORS[sensor]
    c, s = math.cos(pose.heading), math.sin(pose.heading)
    bx, by = along * length / 2, across * width / 2
    ox, oy = pose.x + bx * c - by * s, pose.y + bx * s + by * c
    rays = max(1, int(2 * cone_degrees * RAYS_PER_DEGREE) + 1)
    nearest = reach
    for i in range(rays):
        angle = pose.heading + facing + math.radians(
            -cone_degrees + (2 * cone_degrees * i / (rays - 1) if rays > 1 else cone_degrees))
        dx, dy = math.cos(angle), math.sin(angle)
        for polygon in obstacles:
            hit = ray_polygon(ox, oy, dx, dy, polygon)
            if hit is not None and hit < nearest:
                nearest = hit
    return nearest
