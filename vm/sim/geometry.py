"""Plane geometry: on plain floats where the simulator calls it at every step (numpy's
per-call overhead would cost more than it saves), on numpy arrays where the camera asks
it of every pixel."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

Point = tuple[float, float]
Box = tuple[float, float, float, float]  # x0, y0, x1, y1: the least and the most x and y
Floats = npt.NDArray[np.float64]
Mask = npt.NDArray[np.bool_]


def segment_nearest(px: float, py: float, a: Point, b: Point) -> tuple[float, float, float]:
    """The point of segment ab nearest to (px, py), and its distance."""
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / length2))
    nx, ny = ax + t * dx, ay + t * dy
    return nx, ny, math.hypot(px - nx, py - ny)


def inside(px: float, py: float, polygon: Sequence[Point]) -> bool:
    """Whether (px, py) lies inside `polygon` (even-odd rule)."""
    result = False
    count = len(polygon)
    for i in range(count):
        x1, y1 = polygon[i]
        x2, y2 = polygon[(i + 1) % count]
        if (y1 > py) != (y2 > py) and px < x1 + (py - y1) * (x2 - x1) / (y2 - y1):
            result = not result
    return result


def inside_each(px: Floats, py: Floats, polygon: Sequence[Point]) -> Mask:
    """Whether each point (px, py), broadcast together, lies inside `polygon` (the
    even-odd rule)."""
    result = np.zeros(np.broadcast_shapes(px.shape, py.shape), dtype=bool)
    for i in range(len(polygon)):
        x1, y1 = polygon[i]
        x2, y2 = polygon[(i + 1) % len(polygon)]
        if y1 == y2:
            continue
        crosses = ((y1 > py) != (y2 > py)) & (px < x1 + (py - y1) * (x2 - x1) / (y2 - y1))
        result ^= crosses
    return result


def bounding_box(points: Sequence[Point], reach: float = 0.0) -> Box:
    """The box around `points`, grown by `reach` on every side."""
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    return min(xs) - reach, min(ys) - reach, max(xs) + reach, max(ys) + reach


def boxes_overlap(first: Box, second: Box) -> bool:
    return (first[2] >= second[0] and first[0] <= second[2]
            and first[3] >= second[1] and first[1] <= second[3])


def _crosses(a: Point, b: Point, c: Point, d: Point) -> bool:
    def side(p: Point, q: Point, r: Point) -> float:
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    return (side(a, b, c) * side(a, b, d) < 0) and (side(c, d, a) * side(c, d, b) < 0)


def overlap(first: Sequence[Point], second: Sequence[Point]) -> bool:
    """Whether two simple polygons overlap: an edge crosses, or one holds the other's
    first corner."""
    for i in range(len(first)):
        a, b = first[i], first[(i + 1) % len(first)]
        for j in range(len(second)):
            if _crosses(a, b, second[j], second[(j + 1) % len(second)]):
                return True
    return inside(*first[0], second) or inside(*second[0], first)


def rectangle(cx: float, cy: float, length: float, width: float,
              heading: float) -> list[Point]:
    """The corners of a rectangle centred on (cx, cy), `length` along `heading`
    (radians), counterclockwise from the front left."""
    c, s = math.cos(heading), math.sin(heading)
    corners = ((length / 2, width / 2), (-length / 2, width / 2),
               (-length / 2, -width / 2), (length / 2, -width / 2))
    return [(cx + x * c - y * s, cy + x * s + y * c) for x, y in corners]
