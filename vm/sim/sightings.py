"""What the camera saw at each (IMG) of a run, for the camera panes of the replay page and
of the studio, and the pictures' footprints (spec/simulator.md, "The record of a run"):
the scene and the camera's view, a few numbers each, from which `SightingImages` renders
the binary image again (the image itself, up to 1 Mbit, is never kept).

Bounded whatever the run: the first and the last MAX_SIGHTINGS // 2, and how many were
left out between (a loop polling (IMG) can make millions).
"""

from __future__ import annotations

import base64
from collections import deque
from collections.abc import Iterator
from typing import Any, NamedTuple

import numpy as np

from .camera import Scenery, View
from .world import Scene, World

_EMPTY_SCENE = Scene((), (0, 0, 1, 1))  # a scene the world does not define sees nothing

MAX_SIGHTINGS = 10_000
"""Sightings a run keeps, at most (about 420 bytes each: 4 MB in all)."""


class Sighting(NamedTuple):
    """One (IMG): when it started (s), the scene selected, where the camera was and
    looked, and what it returned (area, x, y)."""

    time: float
    scene: int
    view: View
    reading: tuple[int, int, int]


class Sightings:
    def __init__(self) -> None:
        self._first: list[Sighting] = []
        self._last: deque[Sighting] = deque(maxlen=MAX_SIGHTINGS // 2)
        self.left_out = 0

    def add(self, sighting: Sighting) -> None:
        if len(self._first) < MAX_SIGHTINGS // 2:
            self._first.append(sighting)
            return
        if len(self._last) == self._last.maxlen:
            self.left_out += 1
        self._last.append(sighting)

    def __iter__(self) -> Iterator[Sighting]:
        yield from self._first
        yield from self._last

    def __len__(self) -> int:
        return len(self._first) + len(self._last)

    @property
    def added(self) -> int:
        """The sightings added, those left out included."""
        return len(self) + self.left_out

    @property
    def latest(self) -> Sighting | None:
        """The last sighting added (None: none yet)."""
        if self._last:
            return self._last[-1]
        return self._first[-1] if self._first else None


class SightingImages:
    """The binary image the camera saw at a sighting, rendered again in `world` (each
    scene's Scenery prepared once), as the pages draw it: the replay page's frames and the
    studio's CameraImage (spec/studio.md), the image's rows of bits packed and base64."""

    def __init__(self, world: World) -> None:
        self._world = world
        self._sceneries: dict[int, Scenery] = {}

    def encoded(self, sighting: Sighting) -> dict[str, Any]:
        """{time (s), scene, size (the whole image's columns and rows), left, top (its
        part that holds every set pixel: where it starts), columns, rows, bits, window
        (x0, y0, x1, y1, end exclusive), reading (area, x, y as IMG returned them)}."""
        scenery = self._sceneries.get(sighting.scene)
        if scenery is None:
            scenery = self._sceneries[sighting.scene] = Scenery(
                self._world, self._world.scenes.get(sighting.scene, _EMPTY_SCENE))
        image, (left, top) = scenery.render(sighting.view)
        vehicle = self._world.vehicle
        return {"time": round(sighting.time, 3), "scene": sighting.scene,
                "size": [vehicle.image_width, vehicle.image_height],
                "left": left, "top": top, "columns": image.shape[1], "rows": image.shape[0],
                "bits": base64.b64encode(np.packbits(image, axis=None).tobytes()).decode(),
                "window": list(scenery.window), "reading": list(sighting.reading)}
