"""Line tracing (spec/simulator.md, "Line tracing"): what the image processor measures
of the guidance line at the centre of the camera's view, and the paper's correction law.

The measurement is computed from the geometry, not from a rendered image: the tracing
runs at every timer interval, and rendering there would cost the simulator its speed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
import numpy.typing as npt

from .world import Line

Floats = npt.NDArray[np.float64]

MAX_SPEED = 12  # wheel speed units: the range of MOV and MVI


@dataclass(frozen=True, slots=True)
class LineView:
    """The line as the image processor sees it: `offset` cm to the right of the view's
    centre, `angle` radians to the right of the view's direction (tan(90 - theta))."""

    offset: float
    angle: float


@dataclass(frozen=True, slots=True)
class Segments:
    """Every straight piece of the guidance lines, as arrays: start points, direction
    vectors, squared lengths, half widths, angles. Built once per world, so that a
    measurement at each timer tick is a few array operations."""

    ax: Floats
    ay: Floats
    dx: Floats
    dy: Floats
    length2: Floats
    half_width: Floats
    angle: Floats


def segments(lines: Sequence[Line]) -> Segments:
    pieces = [(a, b, line.width / 2) for line in lines for a, b in pairwise(line.points)]
    ax = np.array([a[0] for a, _, _ in pieces], dtype=float)
    ay = np.array([a[1] for a, _, _ in pieces], dtype=float)
    dx = np.array([b[0] - a[0] for a, b, _ in pieces], dtype=float)
    dy = np.array([b[1] - a[1] for a, b, _ in pieces], dtype=float)
    length2 = dx * dx + dy * dy
    return Segments(ax, ay, dx, dy, np.where(length2 == 0, 1.0, length2),
                    np.array([w for _, _, w in pieces], dtype=float), np.arctan2(dy, dx))


def measure(pieces: Segments, cx: float, cy: float, direction: float,
            half_width: float) -> LineView | None:
    """The guidance line nearest to the view centre (cx, cy) of a view looking along
    `direction` (radians) and `half_width` cm wide either side; None when no line's
    edge is within the view."""
    if pieces.ax.size == 0:
        return None
    t = np.clip(((cx - pieces.ax) * pieces.dx + (cy - pieces.ay) * pieces.dy) / pieces.length2,
                0.0, 1.0)
    nx, ny = pieces.ax + t * pieces.dx, pieces.ay + t * pieces.dy
    gaps = np.maximum(np.hypot(cx - nx, cy - ny) - pieces.half_width, 0.0)
    nearest = int(np.argmin(gaps))
    if gaps[nearest] > half_width:
        return None
    # Offset to the right of the view direction; the line's direction is taken modulo
    # 180 degrees, the way that is nearer the view's.
    offset = ((float(nx[nearest]) - cx) * math.sin(direction)
              - (float(ny[nearest]) - cy) * math.cos(direction))
    relative = (float(pieces.angle[nearest]) - direction + math.pi / 2) % math.pi - math.pi / 2
    return LineView(offset, -relative)


def correct(left: int, right: int, view: LineView, k1: float, k2: float) -> tuple[float, float]:
    """The paper's law: v_d = (v_L + v_R)/2 (K1 dx + K2 tan(90 - theta)),
    V_L = v_L + v_d, V_R = v_R - v_d, each held to the wheels' range."""
    correction = (left + right) / 2 * (k1 * view.offset + k2 * math.tan(view.angle))
    return (max(-MAX_SPEED, min(MAX_SPEED, left + correction)),
            max(-MAX_SPEED, min(MAX_SPEED, right - correction)))
