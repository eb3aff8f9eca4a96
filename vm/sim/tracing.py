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

from .geometry import segment_nearest
from .world import Line

MAX_SPEED = 12  # wheel speed units: the range of MOV and MVI


@dataclass(frozen=True, slots=True)
class LineView:
    """The line as the image processor sees it: `offset` cm to the right of the view's
    centre, `angle` radians to the right of the view's direction (tan(90 - theta))."""

    offset: float
    angle: float


def measure(lines: Sequence[Line], cx: float, cy: float, direction: float,
            half_width: float) -> LineView | None:
    """The guidance line nearest to the view centre (cx, cy) of a view looking along
    `direction` (radians) and `half_width` cm wide either side; None when no line is
    within the view."""
    best: tuple[float, float, float, float] | None = None  # distance, nx, ny, segment angle
    for line in lines:
        for a, b in pairwise(line.points):
            nx, ny, distance = segment_nearest(cx, cy, a, b)
            distance = max(0.0, distance - line.width / 2)
            if best is None or distance < best[0]:
                best = (distance, nx, ny, math.atan2(b[1] - a[1], b[0] - a[0]))
    if best is None or best[0] > half_width:
        return None
    _, nx, ny, segment = best
    # Offset to the right of the view direction; the line's direction is taken modulo
    # 180 degrees, the way that is nearer the view's.
    offset = (nx - cx) * math.sin(direction) - (ny - cy) * math.cos(direction)
    relative = (segment - direction + math.pi / 2) % math.pi - math.pi / 2
    return LineView(offset, -relative)


def correct(left: int, right: int, view: LineView, k1: float, k2: float) -> tuple[float, float]:
    """The paper's law: v_d = (v_L + v_R)/2 (K1 dx + K2 tan(90 - theta)),
    V_L = v_L + v_d, V_R = v_R - v_d, each held to the wheels' range."""
    correction = (left + right) / 2 * (k1 * view.offset + k2 * math.tan(view.angle))
    return (max(-MAX_SPEED, min(MAX_SPEED, left + correction)),
            max(-MAX_SPEED, min(MAX_SPEED, right - correction)))
