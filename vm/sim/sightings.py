"""What the camera saw at each (IMG) of a run, for the replay page's camera pane and the
pictures' footprints (spec/simulator.md, "The record of a run"): the scene and the
camera's view, a few numbers each, from which the picture renders the binary image
again (the image itself, up to 1 Mbit, is never kept).

Bounded whatever the run: the first and the last MAX_SIGHTINGS // 2, and how many were
left out between (a loop polling (IMG) can make millions).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from typing import NamedTuple

from .camera import View

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
