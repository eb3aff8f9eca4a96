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
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from . import occlusion
from .geometry import Box, Floats, Mask, Point, bounding_box, boxes_overlap, inside_each
from .world import LED_RADIUS, Scene, Vehicle, World

PULSES = 784  # the pan motor's travel, 0..784 pulses for 0..180 degrees


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
def _ray_lengths(width: int, height: int, f: float) -> Floats:
    """The length of each pixel's ray f forward + column left + row down (unnormalised),
    shape (rows, columns): the same for every image of a camera."""
    columns, rows = _offsets(width, height, (0, 0, width, height))
    lengths: Floats = np.sqrt(f * f + columns[None, :] ** 2 + rows[:, None] ** 2)
    lengths.setflags(write=False)
    return lengths


@functools.lru_cache(maxsize=16)
def _offsets(width: int, height: int, window: tuple[int, int, int, int]) -> tuple[Floats, Floats]:
    """Each column's and each row's pixel centre in `window`, from the optical axis."""
    x0, y0, x1, y1 = window
    columns = np.arange(x0, x1, dtype=np.float64) + (0.5 - width / 2)
    rows = np.arange(y0, y1, dtype=np.float64) + (0.5 - height / 2)
    columns.setflags(write=False)
    rows.setflags(write=False)
    return columns, rows


Axes = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]


def _axes(view: View) -> Axes:
    """The camera's forward, left and down unit vectors in the world."""
    cp, sp = math.cos(view.pitch), math.sin(view.pitch)
    cy, sy = math.cos(view.yaw), math.sin(view.yaw)
    return (cp * cy, cp * sy, sp), (-sy, cy, 0.0), (sp * cy, sp * sy, -cp)


def _to_camera(view: View) -> Callable[[Point], Point]:
    """A point of the floor plan in the camera's frame turned to the world: cm ahead
    along its yaw and to the left."""
    cy, sy = math.cos(view.yaw), math.sin(view.yaw)

    def local(point: Point) -> Point:
        x, y = point[0] - view.x, point[1] - view.y
        return x * cy + y * sy, y * cy - x * sy

    return local


@dataclass(frozen=True, slots=True)
class _Piece:
    """A straight piece of a guidance line, `half_width` either side of ab."""

    a: Point
    b: Point
    half_width: float
    box: Box  # what it covers on the floor


def _near_piece(ahead: Floats, left: Floats, a: Point, b: Point, half_width: float,
                corners: Sequence[Point]) -> Mask:
    """The floor points (ahead, left) within `half_width` of the segment ab, all in the
    camera's frame, the points all inside the quadrilateral `corners`."""
    (ax, ay), (bx, by) = a, b
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    if length2 and all(0 <= (x - ax) * dx + (y - ay) * dy <= length2 for x, y in corners):
        # Every point seen lies beside the segment, not beyond an end: its distance is
        # the distance to the segment's line.
        length = math.sqrt(length2)
        nx, ny = -dy / length, dx / length
        distance = left * ny
        distance += ahead * nx - (ax * nx + ay * ny)
        return np.abs(distance) <= half_width
    t = np.clip(((ahead - ax) * dx + (left - ay) * dy) / (length2 or 1.0), 0.0, 1.0)
    return np.hypot(ahead - (ax + t * dx), left - (ay + t * dy)) <= half_width


@dataclass(frozen=True, slots=True)
class _Marker:
    """A stand's marker: the middle of its face on the floor plan, the way the face
    looks (a unit vector), its LEDs' heights, and the stand's index in the world."""

    x: float
    y: float
    facing: Point
    leds: tuple[float, float]
    stand: int


@dataclass(frozen=True, slots=True)
class _Ground:
    """Where the window's rows that look down (from `first` on) meet the floor, for one
    pitch of the camera, in its frame turned to the world: cm ahead along its yaw (per
    row) and to the left (per pixel); `corners` those of the window's four corner pixels.
    The yaw only turns this, so it is computed once per pitch."""

    first: int
    ahead: Floats  # shape (rows, 1)
    left: Floats  # shape (rows, columns)
    corners: tuple[Point, Point, Point, Point]


def _led_extent(ahead: float, left: float, down: float,
                f: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """The columns and rows (from the optical axis) that an LED at (ahead, left, down)
    from the camera covers in the image: the box of the ellipse where the cone of rays
    that pass within LED_RADIUS of its centre meets the image plane. The ray through
    (u, v) is p = (f, u, v); it is in the cone when (p.c)^2 >= (|c|^2 - r^2) |p|^2, a
    conic A u^2 + B uv + C v^2 + D u + E v + F >= 0; it is an ellipse while the LED is
    wholly in front (ahead > r). Its extent in u is where, in v, it has one root."""
    r2 = LED_RADIUS * LED_RADIUS
    a = r2 - ahead * ahead - down * down
    b = 2 * left * down
    c = r2 - ahead * ahead - left * left
    d = 2 * f * ahead * left
    e = 2 * f * ahead * down
    g = f * f * (r2 - left * left - down * down)

    def interval(p: float, q: float, r: float) -> tuple[float, float]:
        # Where p x^2 + q x + r >= 0, p < 0: between the roots.
        root = math.sqrt(max(0.0, q * q - 4 * p * r))
        low, high = (-q + root) / (2 * p), (-q - root) / (2 * p)
        return min(low, high), max(low, high)

    shape = b * b - 4 * a * c  # negative for an ellipse
    return (interval(shape, 2 * b * e - 4 * c * d, e * e - 4 * c * g),
            interval(shape, 2 * b * d - 4 * a * e, d * d - 4 * a * g))


_Patch = tuple[int, int, Mask]  # top row and left column in the image, and the pixels


class Scenery:
    """What one scene of a world sees (its lines' pieces, marks and markers) and the
    camera's constants, prepared once, so that each (IMG) only renders."""

    def __init__(self, world: World, scene: Scene) -> None:
        def seen(kind: str, name: str) -> bool:
            return kind in scene.sees or name in scene.sees

        vehicle = world.vehicle
        self.vehicle = vehicle
        self.focal = focal(vehicle)
        x0, y0, x1, y1 = scene.window
        self.window = (x0, y0, min(x1, vehicle.image_width), min(y1, vehicle.image_height))
        self.columns, self.rows = _offsets(vehicle.image_width, vehicle.image_height,
                                           self.window)
        self.pieces = [_Piece(a, b, line.width / 2, bounding_box((a, b), line.width / 2))
                       for line in world.lines if seen("lines", line.name)
                       for a, b in pairwise(line.points)]
        self.marks = [(mark.points, bounding_box(mark.points)) for mark in world.marks
                      if seen("marks", mark.name)]
        self.markers = [_Marker(*stand.marker(), (math.cos(math.radians(stand.facing)),
                                                  math.sin(math.radians(stand.facing))),
                                stand.leds(vehicle.camera_height), i)
                        for i, stand in enumerate(world.stands) if seen("markers", stand.name)]
        self.occluders = occlusion.occluders(world)
        self.all_columns, self.all_rows = _offsets(vehicle.image_width, vehicle.image_height,
                                                   (0, 0, vehicle.image_width,
                                                    vehicle.image_height))
        self.ray_lengths = _ray_lengths(vehicle.image_width, vehicle.image_height, self.focal)
        self._grounds: dict[float, _Ground | None] = {}  # by pitch

    def render(self, view: View) -> tuple[Mask, tuple[int, int]]:
        """The binary image of what the camera at `view` sees, True where a feature is,
        cut to a part of the window that holds every set pixel: the image and its top
        left pixel (column, row)."""
        x0, y0, x1, y1 = self.window
        if x0 >= x1 or y0 >= y1:
            return np.zeros((0, 0), dtype=bool), (x0, y0)
        floor = self._floor(view) if self.pieces or self.marks else None
        patches = self._leds(view, _axes(view)) if self.markers else []
        if floor is None:
            if not patches:
                return np.zeros((0, 0), dtype=bool), (x0, y0)
            # Only the LEDs: the image is the box around their patches.
            top, left, bottom, right = patches[0][0], patches[0][1], 0, 0
            for r0, c0, mask in patches:
                top, left = min(top, r0), min(left, c0)
                bottom, right = max(bottom, r0 + mask.shape[0]), max(right, c0 + mask.shape[1])
            image = np.zeros((bottom - top, right - left), dtype=bool)
        else:
            first, image = floor
            top, left = y0 + first, x0
        for r0, c0, mask in patches:
            r, c = r0 - top, c0 - left
            if r < 0:  # an LED above the rows that look down
                image = np.vstack((np.zeros((-r, image.shape[1]), dtype=bool), image))
                top, r = r0, 0
            image[r:r + mask.shape[0], c:c + mask.shape[1]] |= mask
        return image, (left, top)

    def _ground(self, pitch: float) -> _Ground | None:
        """A pixel's ray is f forward + column left + row down (unnormalised), so its
        drop depends on its row alone: the rows that look down are the last ones, and
        where they meet the floor is, in each row, an affine function of the column."""
        if pitch in self._grounds:
            return self._grounds[pitch]
        cp, sp = math.cos(pitch), math.sin(pitch)
        f = self.focal
        drops = f * sp - self.rows * cp
        down = drops < -1e-9 * f
        ground = None
        if down[-1]:  # rows drop more the lower they are: some look down
            first = int(np.argmax(down))
            scale = self.vehicle.camera_height / -drops[first:]
            ahead = (scale * (f * cp + self.rows[first:] * sp))[:, None]
            left = np.multiply.outer(scale, self.columns)
            ahead.setflags(write=False)
            left.setflags(write=False)
            corners = ((float(ahead[0, 0]), float(left[0, 0])),
                       (float(ahead[0, 0]), float(left[0, -1])),
                       (float(ahead[-1, 0]), float(left[-1, -1])),
                       (float(ahead[-1, 0]), float(left[-1, 0])))
            ground = _Ground(first, ahead, left, corners)
        self._grounds[pitch] = ground
        return ground

    def _floor(self, view: View) -> tuple[int, Mask] | None:
        """The rows of the window from the first that looks down, set where they see a
        line or mark on the floor; None when they see none. The features are brought
        into the camera's frame, rather than every pixel into the world's."""
        ground = self._ground(view.pitch)
        if ground is None:
            return None
        cy, sy = math.cos(view.yaw), math.sin(view.yaw)
        local = _to_camera(view)
        # The window's floor is the projective image of a rectangle: a convex
        # quadrilateral, so its corners bound it.
        world_x = [view.x + a * cy - b * sy for a, b in ground.corners]
        world_y = [view.y + a * sy + b * cy for a, b in ground.corners]
        margin = 1e-6 * (1 + max(map(abs, world_x + world_y)))
        seen = (min(world_x) - margin, min(world_y) - margin,
                max(world_x) + margin, max(world_y) + margin)
        pieces = [piece for piece in self.pieces if boxes_overlap(piece.box, seen)]
        marks = [points for points, box in self.marks if boxes_overlap(box, seen)]
        if not (pieces or marks):
            return None
        image: Mask | None = None
        for piece in pieces:
            near = _near_piece(ground.ahead, ground.left, local(piece.a), local(piece.b),
                               piece.half_width, ground.corners)
            image = near if image is None else image | near
        for points in marks:
            inside = inside_each(ground.ahead, ground.left, [local(p) for p in points])
            image = inside if image is None else image | inside
        assert image is not None
        prisms = self._prisms(view, seen)
        if prisms:
            rows, columns = np.nonzero(image)
            hide = occlusion.hidden(ground.ahead[rows, 0], ground.left[rows, columns], 0.0,
                                    view.z, prisms)
            image[rows[hide], columns[hide]] = False
        return ground.first, image

    def _prisms(self, view: View, seen: Box,
                looked_at: int | None = None) -> list[occlusion.Prism]:
        """What may stand between the camera and what it sees within `seen` (on the
        floor plan), but the stand `looked_at`, in the camera's frame."""
        near = occlusion.near(self.occluders, (view.x, view.y), seen, looked_at)
        if not near:
            return []
        local = _to_camera(view)
        return [([local(point) for point in each.points], each.height) for each in near]

    def _leds(self, view: View, axes: Axes) -> list[_Patch]:
        """The pixels whose rays pass within an LED's radius of its centre, as patches
        of the window: only a box around each LED's projection is tested. A ray at
        angle a to the LED's direction misses its centre by |c| sin a, so it hits when
        its component along c is at least sqrt(|c|^2 - r^2)."""
        f = self.focal
        x0, y0, x1, y1 = self.window
        half_width, half_height = self.vehicle.image_width / 2, self.vehicle.image_height / 2
        patches = []
        for marker in self.markers:
            mx, my = marker.x, marker.y
            if (view.x - mx) * marker.facing[0] + (view.y - my) * marker.facing[1] <= 0:
                continue  # the camera is behind the marker's face
            prisms = self._prisms(view, (mx - LED_RADIUS, my - LED_RADIUS,
                                         mx + LED_RADIUS, my + LED_RADIUS), marker.stand)
            for height in marker.leds:
                cx, cy, cz = mx - view.x, my - view.y, height - view.z
                ahead, left, down = (ax * cx + ay * cy + az * cz for ax, ay, az in axes)
                if ahead <= LED_RADIUS:
                    continue
                (u0, u1), (v0, v1) = _led_extent(ahead, left, down, f)
                # Pixel i's centre is i + 0.5 - width / 2 from the axis; a pixel more
                # each side absorbs the rounding of the extent.
                c0 = max(x0, math.floor(u0 + half_width - 0.5) - 1)
                c1 = min(x1, math.ceil(u1 + half_width - 0.5) + 2)
                r0 = max(y0, math.floor(v0 + half_height - 0.5) - 1)
                r1 = min(y1, math.ceil(v1 + half_height - 0.5) + 2)
                if c0 >= c1 or r0 >= r1:
                    continue
                # The ray's component along c, times its length, against the least.
                along = (self.all_rows[r0:r1, None] * down + f * ahead) + (
                    self.all_columns[c0:c1] * left)
                least = math.sqrt(cx * cx + cy * cy + cz * cz - LED_RADIUS * LED_RADIUS)
                lengths = self.ray_lengths[r0:r1, c0:c1]
                patch = along >= least * lengths
                if prisms:
                    self._hide_led(patch, r0, c0, along, lengths, view, prisms)
                patches.append((r0, c0, patch))
        return patches

    def _hide_led(self, patch: Mask, r0: int, c0: int, along: Floats, lengths: Floats,
                  view: View, prisms: list[occlusion.Prism]) -> None:
        """Clear the pixels of an LED's `patch` (its top left pixel at row r0, column
        c0) that `prisms` hide: each ray is followed to where it passes nearest the
        LED's centre, `along` over its length squared times the ray."""
        rows, columns = np.nonzero(patch)
        u = self.all_columns[c0 + columns]
        v = self.all_rows[r0 + rows]
        t = along[rows, columns] / lengths[rows, columns] ** 2
        cp, sp = math.cos(view.pitch), math.sin(view.pitch)
        # The ray f forward + u left + v down, in the camera's frame turned to the world.
        hide = occlusion.hidden(t * (self.focal * cp + v * sp), t * u,
                                view.z + t * (self.focal * sp - v * cp), view.z, prisms)
        patch[rows[hide], columns[hide]] = False


@dataclass(frozen=True, slots=True)
class Moments:
    """What the image processor reports: area (pixels), centroid (pixels, whole image
    coordinates) and the angle of the principal axis (degrees, from the x axis)."""

    area: int
    x: float
    y: float
    angle: float


@functools.lru_cache(maxsize=4)
def _powers(count: int) -> Floats:
    """For pixels 0..count-1, their centre's coordinate to the powers 0, 1 and 2."""
    centres = np.arange(count) + 0.5
    powers = np.stack((np.ones(count), centres, centres * centres), axis=1)
    powers.setflags(write=False)
    return powers


_POWERS = _powers(1024)  # enough for any image of a valid world's camera


def moments(image: Mask, origin: tuple[int, int]) -> Moments:
    """The zeroth, first and second moments of a binary image whose top left pixel is
    `origin` (column, row)."""
    # Two matrix products give every raw moment: image @ [1 x x^2] sums each row's,
    # [1 y y^2]^T @ that sums them over the rows. Pixel centres are halves, so the sums
    # are exact (far below 2^53) whatever the order of summation.
    rows, columns = image.shape
    reach = max(origin[0] + columns, origin[1] + rows)
    powers = _POWERS if reach <= len(_POWERS) else _powers(reach)
    sums = (powers[origin[1]:origin[1] + rows].T
            @ (image @ powers[origin[0]:origin[0] + columns])).tolist()
    area = sums[0][0]
    if area == 0:
        return Moments(0, 0.0, 0.0, 0.0)
    cx, cy = sums[0][1] / area, sums[1][0] / area
    mu20 = sums[0][2] / area - cx * cx
    mu02 = sums[2][0] / area - cy * cy
    mu11 = sums[1][1] / area - cx * cy
    if abs(mu11) < 1e-9 * (mu20 + mu02):
        mu11 = 0.0  # rounding noise would flip a vertical axis between -90 and 90
    return Moments(int(area), cx, cy, math.degrees(0.5 * math.atan2(2 * mu11, mu20 - mu02)))


def view_centre(view: View) -> tuple[float, float, float] | None:
    """Where the optical axis meets the floor and the slant range to it; None when
    the camera looks level or up."""
    if view.pitch >= 0:
        return None
    reach = view.z / math.tan(-view.pitch)
    return (view.x + reach * math.cos(view.yaw), view.y + reach * math.sin(view.yaw),
            view.z / math.sin(-view.pitch))
