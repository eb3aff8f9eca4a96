"""What stands between the camera and what it looks at (spec/simulator.md, "Camera and
image processor"): walls, obstacles and stands are upright prisms on the floor, each as
high as the world says, and a pixel whose ray meets one before what it looks at is
hidden. Lines and marks are flat and the LEDs small: they hide nothing."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .geometry import Box, Floats, Mask, Point, bounding_box, boxes_overlap, inside_each
from .world import World


@dataclass(frozen=True, slots=True)
class Occluder:
    """A prism standing on the floor: its footprint, its top's height (cm), the box
    around the footprint, and which stand it is, if one (a stand does not hide its own
    marker, which is on its face)."""

    points: tuple[Point, ...]
    height: float
    box: Box
    stand: int | None


def occluders(world: World) -> tuple[Occluder, ...]:
    """Every stand, wall and obstacle of `world`."""
    stands = [(tuple(stand.corners()), stand.height, i) for i, stand in enumerate(world.stands)]
    blocks = [(block.points, block.height, None) for block in world.blocks]
    return tuple(Occluder(points, height, bounding_box(points), stand)
                 for points, height, stand in stands + blocks)


def near(candidates: Sequence[Occluder], camera: Point, seen: Box,
         looked_at: int | None = None) -> list[Occluder]:
    """Those of `candidates` that may stand between a camera at `camera` (on the floor
    plan) and what it sees within `seen`: those in the box around both, but the stand
    `looked_at` whose marker is seen."""
    box = (min(seen[0], camera[0]), min(seen[1], camera[1]),
           max(seen[2], camera[0]), max(seen[3], camera[1]))
    return [each for each in candidates
            if (each.stand is None or each.stand != looked_at) and boxes_overlap(each.box, box)]


Prism = tuple[Sequence[Point], float]  # a footprint in the camera's frame, and its height


def hidden(ahead: Floats, left: Floats, height: Floats | float, camera_height: float,
           prisms: Sequence[Prism]) -> Mask:
    """Whether the ray from the camera, at (0, 0, camera_height), to each point (ahead,
    left, height) meets one of `prisms` before it: it crosses a side under the top, or
    ends inside a footprint under the top (having come in over it)."""
    result = np.zeros(ahead.shape, dtype=bool)
    rise = height - camera_height
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for points, top in prisms:
            result |= inside_each(ahead, left, points) & (height < top)
            for i, (ax, ay) in enumerate(points):
                bx, by = points[(i + 1) % len(points)]
                ex, ey = bx - ax, by - ay
                # The ray's track on the floor, s p for 0 < s < 1 (p = (ahead, left)),
                # meets the side a + u e, 0 <= u <= 1, at s = (a x e) / (p x e) and
                # u = (a x p) / (p x e); parallel, or nearly, it gives inf or nan.
                across = ahead * ey - left * ex
                s = (ax * ey - ay * ex) / across
                u = (ax * left - ay * ahead) / across
                result |= ((s > 0) & (s < 1) & (u >= 0) & (u <= 1)
                           & (camera_height + s * rise < top))
    return result
