"""Small worlds for the simulator's tests, built in code so each test shows its scene."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import msgspec

from rl1.vm.sim.world import Line, Scene, Stand, Vehicle, World


def open_floor(x: float = 500.0, y: float = 500.0, heading: float = 0.0,
               **vehicle: Any) -> World:
    """A 1000 x 1000 cm floor with nothing on it, the vehicle at (x, y)."""
    return World(floor=(1000.0, 1000.0), start=(x, y, heading),
                 vehicle=msgspec.structs.replace(Vehicle(), **vehicle))


def line_world(offset: float = 0.0, angle: float = 0.0) -> World:
    """A straight guidance line along y = 500, the vehicle starting `offset` cm to its
    left and `angle` degrees off its direction."""
    return replace(open_floor(100.0, 500.0 + offset, angle),
                   lines=(Line("guide", ((0.0, 500.0), (1000.0, 500.0)), 2.0),),
                   scenes={0: Scene(("lines", "marks"), (0, 0, 256, 240))})


def stand_world(distance: float) -> World:
    """A stand whose marker faces the vehicle `distance` cm ahead of its camera."""
    world = open_floor(200.0, 500.0)
    marker_x = 200.0 + world.vehicle.camera_ahead + distance
    return replace(world, stands=(Stand("stand", marker_x + 20.0, 500.0, 40.0, 40.0, 180.0),),
                   scenes={2: Scene(("markers",), (0, 0, 256, 240))})


def round_track() -> World:
    """A round guidance track of radius 200 cm (72 straight pieces) centred on a 6 m
    floor, a stand in its middle, the vehicle on it facing along it (bench/sim_speed.py's
    patrol)."""
    points = tuple((300 + 200 * math.cos(math.radians(a)), 300 + 200 * math.sin(math.radians(a)))
                   for a in range(0, 361, 5))
    return World(floor=(600.0, 600.0), start=(500.0, 300.0, 90.0),
                 lines=(Line("track", points, 2.0),),
                 stands=(Stand("stand", 300.0, 300.0, 40.0, 40.0, 0.0),),
                 scenes={0: Scene(("lines",), (98, 117, 158, 123))}, time_limit=900.0)
