"""The camera and the image processor (spec/simulator.md, "Camera"): a pinhole camera on
a pan-tilt head renders what a scene sees into a binary image (numpy), and the image's
moments give what (IMG) returns.

Image coordinates: x grows to the left as seen from the vehicle, y grows downward;
pixel (column i, row j) has its centre at (i + 0.5, j + 0.5), so the optical axis falls
on (width / 2, height / 2) exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
import numpy.typing as npt

from .world import Scene, Vehicle, World

Floats = npt.NDArray[np.float64]
Mask = npt.NDArray[np.bool_]

PULSES = 784  # the pan motor's travel, 0..784 pulses for 0..180 degrees
LED_SPACING = 6.0  # cm between the marker's two LEDs (Fig. 3)
LED_RADIUS = 1.0  # cm


def pulse_angle(pulse: float) -> float:
    """The pan angle in radians, + left of straight ahead, of a pulse position (392 is
    straight ahead, 784 fully left)."""
    return math.radians(pulse * 180 / PULSES - 90)


@dataclass(frozen=True, slots=True)
class View:
    """Where the camera is and looks: its centre (cm), yaw (radians from +x) and
    pitch (radians, negative when looking down)."""

    x: float
    y: float
    z: float
    yaw: float
    pitch: float


def view_of(x: float, y: float, heading: float, pan_pulse: float, tilt: float,
            vehicle: Vehicle) -> View:
    return View(x + vehicle.camera_ahead * math.cos(heading),
                y + vehicle.camera_ahead * math.sin(heading), vehicle.camera_height,
                heading + pulse_angle(pan_pulse), -tilt)


def focal(vehicle: Vehicle) -> float:
    """The focal length in pixels."""
    return vehicle.image_width / 2 / math.tan(math.radians(vehicle.camera_fov) / 2)


def rays(view: View, vehicle: Vehicle, window: tuple[int, int, int, int]) -> Floats:
    """Unit ray directions for each pixel of `window`, shape (rows, columns, 3)."""
    x0, y0, x1, y1 = window
    x1, y1 = min(x1, vehicle.image_width), min(y1, vehicle.image_height)
    xs = np.arange(x0, x1) + 0.5 - vehicle.image_width / 2
    ys = np.arange(y0, y1) + 0.5 - vehicle.image_height / 2
    cp, sp = math.cos(view.pitch), math.sin(view.pitch)
    cy, sy = math.cos(view.yaw), math.sin(view.yaw)
    forward = np.array([cp * cy, cp * sy, sp]) * focal(vehicle)
    left = np.array([-sy, cy, 0.0])  # x grows to the left
    down = np.array([sp * cy, sp * sy, -cp])
    directions = (forward[None, None, :] + xs[None, :, None] * left[None, None, :]
                  + ys[:, None, None] * down[None, None, :])
    result: Floats = directions / np.linalg.norm(directions, axis=2, keepdims=True)
    return result


def _floor_points(view: View, directions: Floats) -> tuple[Floats, Floats, Mask]:
    dz = directions[..., 2]
    down = dz < -1e-9
    t = np.where(down, -view.z / np.where(down, dz, -1.0), 0.0)
    return view.x + t * directions[..., 0], view.y + t * directions[..., 1], down


def _near_polyline(px: Floats, py: Floats, points: tuple[tuple[float, float], ...],
                   half_width: float) -> Mask:
    hit = np.zeros(px.shape, dtype=bool)
    for (ax, ay), (bx, by) in pairwise(points):
        dx, dy = bx - ax, by - ay
        length2 = dx * dx + dy * dy or 1.0
        t = np.clip(((px - ax) * dx + (py - ay) * dy) / length2, 0.0, 1.0)
        hit |= np.hypot(px - (ax + t * dx), py - (ay + t * dy)) <= half_width
    return hit


def _in_polygon(px: Floats, py: Floats, polygon: tuple[tuple[float, float], ...]) -> Mask:
    inside = np.zeros(px.shape, dtype=bool)
    for i in range(len(polygon)):
        x1, y1 = polygon[i]
        x2, y2 = polygon[(i + 1) % len(polygon)]
        if y1 == y2:
            continue
        crosses = ((y1 > py) != (y2 > py)) & (px < x1 + (py - y1) * (x2 - x1) / (y2 - y1))
        inside ^= crosses
    return inside


def _seen(scene: Scene, kind: str, name: str) -> bool:
    return kind in scene.sees or name in scene.sees


def render(world: World, scene: Scene, view: View) -> Mask:
    """The binary image of `scene`'s window as the camera at `view` sees it: True where
    a feature the scene sees is."""
    directions = rays(view, world.vehicle, scene.window)
    image = np.zeros(directions.shape[:2], dtype=bool)
    floor_features = [line for line in world.lines if _seen(scene, "lines", line.name)]
    marks = [mark for mark in world.marks if _seen(scene, "marks", mark.name)]
    if floor_features or marks:
        px, py, down = _floor_points(view, directions)
        for line in floor_features:
            image |= down & _near_polyline(px, py, line.points, line.width / 2)
        for mark in marks:
            image |= down & _in_polygon(px, py, mark.points)
    for stand in world.stands:
        if not _seen(scene, "markers", stand.name):
            continue
        mx, my = stand.marker()
        facing = math.radians(stand.facing)
        if (view.x - mx) * math.cos(facing) + (view.y - my) * math.sin(facing) <= 0:
            continue  # the camera is behind the marker's face
        for height in (world.vehicle.camera_height, world.vehicle.camera_height - LED_SPACING):
            centre = np.array([mx - view.x, my - view.y, height - view.z])
            along = directions @ centre
            miss2 = float(centre @ centre) - along * along
            image |= (along > 0) & (miss2 <= LED_RADIUS * LED_RADIUS)
    return image


@dataclass(frozen=True, slots=True)
class Moments:
    """What the image processor reports: area (pixels), centroid (pixels, whole image
    coordinates) and the angle of the principal axis (degrees, from the x axis)."""

    area: int
    x: float
    y: float
    angle: float


def moments(image: Mask, window: tuple[int, int, int, int]) -> Moments:
    """The zeroth, first and second moments of a binary image whose top left pixel is
    (window[0], window[1])."""
    rows, columns = np.nonzero(image)
    area = int(rows.size)
    if area == 0:
        return Moments(0, 0.0, 0.0, 0.0)
    xs = columns + window[0] + 0.5
    ys = rows + window[1] + 0.5
    cx, cy = float(xs.mean()), float(ys.mean())
    mu20 = float(((xs - cx) ** 2).mean())
    mu02 = float(((ys - cy) ** 2).mean())
    mu11 = float(((xs - cx) * (ys - cy)).mean())
    if abs(mu11) < 1e-9 * (mu20 + mu02):
        mu11 = 0.0  # rounding noise would flip a vertical axis between -90 and 90
    return Moments(area, cx, cy, math.degrees(0.5 * math.atan2(2 * mu11, mu20 - mu02)))


def view_centre(view: View) -> tuple[float, float, float] | None:
    """Where the optical axis meets the floor and the slant range to it; None when
    the camera looks level or up."""
    if view.pitch >= 0:
        return None
    reach = view.z / math.tan(-view.pitch)
    return (view.x + reach * math.cos(view.yaw), view.y + reach * math.sin(view.yaw),
            view.z / math.sin(-view.pitch))
