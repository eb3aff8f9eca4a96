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

from .geometry import Point, segment_nearest
from .world import Line

MAX_SPEED = 12  # wheel speed units: the range of MOV and MVI


@dataclass(frozen=True, slots=True)
class LineView:
    """The line as the image processor sees it: `offset` cm to the right of the view's
    centre, `angle` radians to the right of the view's direction (tan(90 - theta))."""

    offset: float
    angle: float


CELL = 25.0  # cm: the side of a cell of the lines' index, on a floor of a few metres
MOST_SAMPLES = 100_000  # the index's size, whatever the lines' length


@dataclass(frozen=True, slots=True)
class Piece:
    """One straight piece of a guidance line."""

    a: Point
    b: Point
    half_width: float
    angle: float  # radians, from a to b


class LineIndex:
    """The guidance lines' pieces, filed by the square cells of the floor that points
    sampled along each piece fall in, so that a measurement at each timer tick looks at
    a few pieces near the view rather than at all of them. The cells grow with the
    lines' total length, so that the index stays small on any floor."""

    def __init__(self, lines: Sequence[Line]) -> None:
        self.pieces = [Piece(a, b, line.width / 2, math.atan2(b[1] - a[1], b[0] - a[0]))
                       for line in lines for a, b in pairwise(line.points)]
        self.widest = max((piece.half_width for piece in self.pieces), default=0.0)
        total = sum(math.dist(piece.a, piece.b) for piece in self.pieces)
        self.cell = max(CELL, 2 * total / MOST_SAMPLES)
        self.spacing = self.cell / 2  # between two samples along a piece
        self.cells: dict[tuple[int, int], list[int]] = {}
        for index, piece in enumerate(self.pieces):
            (ax, ay), (bx, by) = piece.a, piece.b
            samples = math.ceil(math.dist(piece.a, piece.b) / self.spacing) + 1
            filed = {(math.floor((ax + (bx - ax) * k / (samples - 1 or 1)) / self.cell),
                      math.floor((ay + (by - ay) * k / (samples - 1 or 1)) / self.cell))
                     for k in range(samples)}
            for cell in filed:
                self.cells.setdefault(cell, []).append(index)

    def near(self, x: float, y: float, reach: float) -> set[int]:
        """The pieces filed within `reach` of (x, y), widened by the samples' spacing:
        every piece that comes that near is among them, since each of its points is
        within the spacing of a sample. A reach wider than the filed cells (a line
        a kilometre wide makes one) looks at those cells rather than at the square's."""
        reach += self.spacing
        cell = self.cell
        low_i, high_i = math.floor((x - reach) / cell), math.floor((x + reach) / cell)
        low_j, high_j = math.floor((y - reach) / cell), math.floor((y + reach) / cell)
        found: set[int] = set()
        if (high_i - low_i + 1) * (high_j - low_j + 1) > len(self.cells):
            for (i, j), numbers in self.cells.items():
                if low_i <= i <= high_i and low_j <= j <= high_j:
                    found.update(numbers)
            return found
        for i in range(low_i, high_i + 1):
            for j in range(low_j, high_j + 1):
                found.update(self.cells.get((i, j), ()))
        return found


def measure(index: LineIndex, cx: float, cy: float, direction: float,
            half_width: float) -> LineView | None:
    """The guidance line nearest to the view centre (cx, cy) of a view looking along
    `direction` (radians) and `half_width` cm wide either side; None when no line's
    edge is within the view."""
    best: tuple[float, float, float, float] | None = None  # gap, nx, ny, piece angle
    for number in sorted(index.near(cx, cy, half_width + index.widest)):  # a fixed order
        piece = index.pieces[number]
        nx, ny, distance = segment_nearest(cx, cy, piece.a, piece.b)
        gap = max(0.0, distance - piece.half_width)
        if best is None or gap < best[0]:
            best = (gap, nx, ny, piece.angle)
    if best is None or best[0] > half_width:
        return None
    _, nx, ny, angle = best
    # Offset to the right of the view direction; the line's direction is taken modulo
    # 180 degrees, the way that is nearer the view's.
    offset = (nx - cx) * math.sin(direction) - (ny - cy) * math.cos(direction)
    relative = (angle - direction + math.pi / 2) % math.pi - math.pi / 2
    return LineView(offset, -relative)


def correct(left: int, right: int, view: LineView, k1: float, k2: float) -> tuple[float, float]:
    """The paper's law: v_d = (v_L + v_R)/2 (K1 dx + K2 tan(90 - theta)),
    V_L = v_L + v_d, V_R = v_R - v_d, each held to the wheels' range."""
    correction = (left + right) / 2 * (k1 * view.offset + k2 * math.tan(view.angle))
    return (max(-MAX_SPEED, min(MAX_SPEED, left + correction)),
            max(-MAX_SPEED, min(MAX_SPEED, right - correction)))
