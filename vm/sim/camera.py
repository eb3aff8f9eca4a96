"""The camera and the image processor (spec/simulator.md, "Camera"): a pinhole camera on
a pan-tilt head renders what a scene sees into a binary image (numpy), and the image's
moments give what (IMG) returns.

Image coordinates: x grows to the left as seen from the vehicle, y grows downward;
pixel (column i, row j) has its centre at (i + 0.5, j + 0.5), so the optical axis falls
on (width / 2, height / 2) exactly.
"""

from __future__ import annotations

import functools
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


@functools.lru_cache(maxsize=8)
def _camera_rays(width: int, height: int, fov: float,
                 window: tuple[int, int, int, int]) -> Floats:
    """Unit ray directions for each pixel of `window` in the camera's frame (forward,
    left, down), shape (rows, columns, 3): the same for every image of a camera."""
    x0, y0, x1, y1 = window
    xs = np.arange(x0, min(x1, width)) + 0.5 - width / 2
    ys = np.arange(y0, min(y1, height)) + 0.5 - height / 2
    f = width / 2 / math.tan(math.radians(fov) / 2)
    directions = np.empty((ys.size, xs.size, 3))
    directions[..., 0] = f
    directions[..., 1] = xs[None, :]  # x grows to the left
    directions[..., 2] = ys[:, None]
    result: Floats = directions / np.linalg.norm(directions, axis=2, keepdims=True)
    result.setflags(write=False)
    return result


def _axes(view: View) -> Floats:
    """The camera's forward, left and down unit vectors in the world, as rows."""
    cp, sp = math.cos(view.pitch), math.sin(view.pitch)
    cy, sy = math.cos(view.yaw), math.sin(view.yaw)
    return np.array([[cp * cy, cp * sy, sp], [-sy, cy, 0.0], [sp * cy, sp * sy, -cp]])


def rays(view: View, vehicle: Vehicle, window: tuple[int, int, int, int]) -> Floats:
    """Unit ray directions in the world for each pixel of `window`, shape
    (rows, columns, 3)."""
    x0, y0, x1, y1 = window
    local = _camera_rays(vehicle.image_width, vehicle.image_height, vehicle.camera_fov,
                         (0, 0, vehicle.image_width, vehicle.image_height))[y0:y1, x0:x1]
    result: Floats = local @ _axes(view)
    return result


def _floor_points(view: View, directions: Floats) -> tuple[Floats, Floats, Mask]:
    dz = directions[..., 2]
    down = dz < -1e-9
    t = np.where(down, -view.z / np.where(down, dz, -1.0), 0.0)
    return view.x + t * directions[..., 0], view.y + t * directions[..., 1], down


def _near_polyline(px: Floats, py: Floats, points: tuple[tuple[float, float], ...],
                   half_width: float, box: tuple[float, float, float, float]) -> Mask:
    hit = np.zeros(px.shape, dtype=bool)
    for (ax, ay), (bx, by) in pairwise(points):
        if (max(ax, bx) + half_width < box[0] or min(ax, bx) - half_width > box[2]
                or max(ay, by) + half_width < box[1] or min(ay, by) - half_width > box[3]):
            continue  # the piece is nowhere near what the camera sees
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


def _floor(world: World, scene: Scene, view: View, image: Mask) -> None:
    """Set the pixels of `image` that see a line or mark of `scene` on the floor."""
    lines = [line for line in world.lines if _seen(scene, "lines", line.name)]
    marks = [mark for mark in world.marks if _seen(scene, "marks", mark.name)]
    if not (lines or marks):
        return
    px, py, down = _floor_points(view, rays(view, world.vehicle, scene.window))
    if not down.any():
        return
    box = (float(px[down].min()), float(py[down].min()),
           float(px[down].max()), float(py[down].max()))
    for line in lines:
        image |= down & _near_polyline(px, py, line.points, line.width / 2, box)
    for mark in marks:
        xs, ys = [p[0] for p in mark.points], [p[1] for p in mark.points]
        if max(xs) >= box[0] and min(xs) <= box[2] and max(ys) >= box[1] and min(ys) <= box[3]:
            image |= down & _in_polygon(px, py, mark.points)


def _leds(world: World, scene: Scene, view: View, image: Mask) -> None:
    """Set the pixels of `image` whose rays pass within an LED's radius of its centre;
    only a box around each LED's projection is tested."""
    vehicle = world.vehicle
    axes = _axes(view)
    f = focal(vehicle)
    x0, y0 = scene.window[0], scene.window[1]
    rows, columns = image.shape
    for stand in world.stands:
        if not _seen(scene, "markers", stand.name):
            continue
        mx, my = stand.marker()
        facing = math.radians(stand.facing)
        if (view.x - mx) * math.cos(facing) + (view.y - my) * math.sin(facing) <= 0:
            continue  # the camera is behind the marker's face
        for height in (vehicle.camera_height, vehicle.camera_height - LED_SPACING):
            centre = np.array([mx - view.x, my - view.y, height - view.z])
            ahead, left, down = (float(v) for v in axes @ centre)
            if ahead <= LED_RADIUS:
                continue
            u = vehicle.image_width / 2 + f * left / ahead - x0
            v = vehicle.image_height / 2 + f * down / ahead - y0
            reach = 2 * f * LED_RADIUS / ahead + 2  # generous: the box only saves work
            c0, c1 = max(0, int(u - reach)), min(columns, int(u + reach) + 1)
            r0, r1 = max(0, int(v - reach)), min(rows, int(v + reach) + 1)
            if c0 >= c1 or r0 >= r1:
                continue
            window = (x0 + c0, y0 + r0, x0 + c1, y0 + r1)
            directions = rays(view, vehicle, window)
            along = directions @ centre
            miss2 = float(centre @ centre) - along * along
            image[r0:r1, c0:c1] |= (along > 0) & (miss2 <= LED_RADIUS * LED_RADIUS)


def render(world: World, scene: Scene, view: View) -> Mask:
    """The binary image of `scene`'s window as the camera at `view` sees it: True where
    a feature the scene sees is."""
    x0, y0, x1, y1 = scene.window
    shape = (min(y1, world.vehicle.image_height) - y0, min(x1, world.vehicle.image_width) - x0)
    image = np.zeros((max(shape[0], 0), max(shape[1], 0)), dtype=bool)
    if image.size:
        _floor(world, scene, view, image)
        _leds(world, scene, view, image)
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
    # Only the box around what is set is summed; the sums over rows and columns are
    # matrix products, cheaper than listing the pixels.
    rows, columns = np.flatnonzero(image.any(axis=1)), np.flatnonzero(image.any(axis=0))
    if rows.size == 0:
        return Moments(0, 0.0, 0.0, 0.0)
    image = image[rows[0]:rows[-1] + 1, columns[0]:columns[-1] + 1]
    window = (window[0] + int(columns[0]), window[1] + int(rows[0]), window[2], window[3])
    pixels = image.astype(np.float64)
    column_counts, row_counts = pixels.sum(axis=0), pixels.sum(axis=1)
    area = int(column_counts.sum())
    if area == 0:
        return Moments(0, 0.0, 0.0, 0.0)
    xs = np.arange(image.shape[1]) + window[0] + 0.5
    ys = np.arange(image.shape[0]) + window[1] + 0.5
    cx, cy = float(column_counts @ xs) / area, float(row_counts @ ys) / area
    mu20 = float(column_counts @ (xs - cx) ** 2) / area
    mu02 = float(row_counts @ (ys - cy) ** 2) / area
    mu11 = float((ys - cy) @ (pixels @ (xs - cx))) / area
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
