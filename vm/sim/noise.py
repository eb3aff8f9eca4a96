"""The vehicle's imperfections (spec/simulator.md, "Noise"): what its sensors report
against what is, how its wheels and steering obey, and where it starts, drawn from
generators seeded by the run's seed, so that the same seed gives the same run.

Each source of noise draws from a generator of its own, so that a program that reads
one sensor more often does not change what another reports; the errors drawn once a run
are drawn whatever their settings, so that setting one leaves the others' draws alone.
A setting of 0 changes nothing: with NOISELESS every value passes through exactly.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from .camera import Moments
from .motion import Pose
from .tracing import LineView
from .world import Noise

_BLOCK = 256  # draws fetched from numpy at once: one call each would cost the run its speed
_CM_PER_METRE = 100.0

# The generators, each numbered into the seed (np.random.SeedSequence), so that adding
# one never changes another's draws.
_START, _ONCE, _SLIP, _ULTRASONIC, _IMAGE, _LINE = range(6)


class _Draws:
    """Draws of one distribution (a numpy generator's method), fetched in blocks."""

    def __init__(self, draw: Callable[[int], npt.NDArray[np.float64]]) -> None:
        self._draw = draw
        self._next: Callable[[], float] = iter(()).__next__

    def __call__(self) -> float:
        try:
            return self._next()
        except StopIteration:
            self._next = iter(self._draw(_BLOCK).tolist()).__next__
            return self._next()


def _normals(seed: int, stream: int) -> _Draws:
    return _Draws(np.random.default_rng([stream, seed]).standard_normal)


def _wrap(angle: float, half_turn: float) -> float:
    """An axis' angle (a direction taken modulo `half_turn`) within
    (-half_turn / 2, half_turn / 2], as the moments and the tracing give it."""
    return half_turn / 2 - (half_turn / 2 - angle) % half_turn


class Imperfections:
    """One run's imperfections: the errors drawn once (each wheel's speed and scale, the
    steering's offset) and the generators of those drawn at each use."""

    def __init__(self, noise: Noise, seed: int) -> None:
        self.noise = noise
        once = _normals(seed, _ONCE)
        # Relative errors: a motor's speed against its command (the counters see it), a
        # wheel's travel on the floor against its counter (they do not).
        self.speed = (1 + noise.wheel_speed * once(), 1 + noise.wheel_speed * once())
        self.scale = (1 + noise.odometry * once(), 1 + noise.odometry * once())
        self.steering = math.radians(noise.steering_deg * once())  # + left
        self._start = _normals(seed, _START)
        self._slip = _normals(seed, _SLIP)
        self._slip_per_cm = noise.slip / math.sqrt(_CM_PER_METRE)  # cm per sqrt(cm)
        self._echo = _normals(seed, _ULTRASONIC)
        self._dropout = _Draws(np.random.default_rng([_ULTRASONIC, seed, 1]).random)
        self._image = _normals(seed, _IMAGE)
        self._line = _normals(seed, _LINE)
        self.moves = self.speed != (1.0, 1.0) or self.scale != (1.0, 1.0) or bool(noise.slip)

    def start(self, pose: Pose) -> Pose:
        """Where the vehicle really starts when the world says `pose`."""
        noise, normal = self.noise, self._start
        if not (noise.start_cm or noise.start_deg):
            return pose
        return Pose(pose.x + noise.start_cm * normal(), pose.y + noise.start_cm * normal(),
                    pose.heading + math.radians(noise.start_deg * normal()))

    def wheels(self, left: float, right: float) -> tuple[float, float]:
        """The wheels' speeds (cm/s, as their counters measure them) under the command
        `left`, `right` cm/s."""
        return left * self.speed[0], right * self.speed[1]

    def ground(self, left: float, right: float, seconds: float) -> tuple[float, float]:
        """The wheels' mean speeds on the floor over `seconds` in which they turned at
        `left`, `right` cm/s by their counters: each off by its scale error, and by slip,
        a random walk whose variance grows with the distance the wheel turns."""
        if not self.moves or seconds <= 0:
            return left, right
        slip = self._slip_per_cm
        if slip:  # over the travel t = speed x seconds, slip x sqrt(t), as a mean speed
            left += slip * math.sqrt(abs(left) / seconds) * self._slip()
            right += slip * math.sqrt(abs(right) / seconds) * self._slip()
        return left * self.scale[0], right * self.scale[1]

    def ultrasonic(self, distance: float, reach: float) -> float:
        """What a sensor reports of the nearest surface `distance` cm away (`reach`: none
        within its reach): no echo reads `reach`, as does a dropout; an echo, its
        distance with noise, held within what the sensor can report (its blind zone's
        end up to `reach`)."""
        noise = self.noise
        if distance >= reach:
            return reach
        if noise.ultrasonic_dropout and self._dropout() < noise.ultrasonic_dropout:
            return reach
        if noise.ultrasonic_cm:
            distance += noise.ultrasonic_cm * self._echo()
        return min(reach, max(min(noise.ultrasonic_blind, reach), distance))

    def image(self, found: Moments, window: tuple[int, int, int, int]) -> Moments:
        """What the image processor reports of `found` in `window` (x0, y0, x1, y1): an
        area of at least one pixel and at most the window's, a centroid within the
        window's pixel centres, the axis' angle within (-90, 90] degrees. An empty
        image stays empty: noise neither hides a feature nor makes one up."""
        noise, normal = self.noise, self._image
        if not found.area or not (noise.image_px or noise.image_area or noise.image_deg):
            return found
        x0, y0, x1, y1 = window
        area = found.area * (1 + noise.image_area * normal()) if noise.image_area else found.area
        x = found.x + noise.image_px * normal() if noise.image_px else found.x
        y = found.y + noise.image_px * normal() if noise.image_px else found.y
        angle = found.angle + noise.image_deg * normal() if noise.image_deg else found.angle
        return Moments(max(1, min((x1 - x0) * (y1 - y0), round(area))),
                       min(x1 - 0.5, max(x0 + 0.5, x)), min(y1 - 0.5, max(y0 + 0.5, y)),
                       _wrap(angle, 180.0))

    def line(self, view: LineView | None) -> LineView | None:
        """What the image processor measures of the traced line `view` at one tick."""
        noise, normal = self.noise, self._line
        if view is None or not (noise.line_cm or noise.line_deg):
            return view
        return LineView(view.offset + noise.line_cm * normal(),
                        _wrap(view.angle + math.radians(noise.line_deg * normal()), math.pi))
