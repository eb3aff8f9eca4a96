"""The ultrasonic range sensors A-D (spec/simulator.md, "Ultrasonic"): the nearest echo
in each sensor's cone from walls, obstacles and stands."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from .geometry import Point
from .motion import Pose

Floats = npt.NDArray[np.float64]

# Where each sensor sits, as fractions of the body's half length and half width, and
# the way it looks (radians from the heading): A front, B right, C rear, D left.
SENSORS: dict[str, tuple[float, float, float]] = {
    "A": (1.0, 0.0, 0.0),
    "B": (0.0, -1.0, -math.pi / 2),
    "C": (-1.0, 0.0, math.pi),
    "D": (0.0, 1.0, math.pi / 2),
}
RAYS_PER_DEGREE = 1  # the cone is sampled by rays this many per degree


class Echoes:
    """Every edge of the obstacles as arrays (start points and edge vectors), built
    once per world: a reading casts all the cone's rays against all edges at once."""

    def __init__(self, obstacles: Sequence[Sequence[Point]]) -> None:
        edges = [(polygon[i], polygon[(i + 1) % len(polygon)])
                 for polygon in obstacles for i in range(len(polygon))]
        self.ax = np.array([a[0] for a, _ in edges], dtype=float)
        self.ay = np.array([a[1] for a, _ in edges], dtype=float)
        self.ex = np.array([b[0] - a[0] for a, b in edges], dtype=float)
        self.ey = np.array([b[1] - a[1] for a, b in edges], dtype=float)


def sense(sensor: str, pose: Pose, length: float, width: float, cone_degrees: float,
          reach: float, echoes: Echoes) -> float:
    """The distance in cm from `sensor` to the nearest surface in its cone, `reach`
    when there is none nearer."""
    if echoes.ax.size == 0:
        return reach
    along, across, facing = SENSORS[sensor]
    c, s = math.cos(pose.heading), math.sin(pose.heading)
    bx, by = along * length / 2, across * width / 2
    ox, oy = pose.x + bx * c - by * s, pose.y + bx * s + by * c
    rays = max(1, int(2 * cone_degrees * RAYS_PER_DEGREE) + 1)
    angles = pose.heading + facing + np.radians(np.linspace(-cone_degrees, cone_degrees, rays)
                                                if rays > 1 else np.zeros(1))
    dx, dy = np.cos(angles)[:, None], np.sin(angles)[:, None]
    # Ray o + t d meets edge a + u e where t = (w x e) / (d x e), u = (w x d) / (d x e),
    # w = a - o; a hit needs t >= 0 and 0 <= u <= 1.
    wx, wy = echoes.ax - ox, echoes.ay - oy
    with np.errstate(divide="ignore", invalid="ignore"):
        denominator = dx * echoes.ey - dy * echoes.ex
        t = (wx * echoes.ey - wy * echoes.ex) / denominator
        u = (wx * dy - wy * dx) / denominator
    hits = t[(denominator != 0) & (t >= 0) & (u >= 0) & (u <= 1)]
    return min(reach, float(hits.min())) if hits.size else reach
