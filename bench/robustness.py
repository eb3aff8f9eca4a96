"""How robust Listing 1 is on the scene of Fig. 4 (spec/simulator.md, "The paper's
reading"): on the sample world and its mirror, the share of seeded runs that succeed at
the default noise (the world's, or the defaults reasoned from the paper's vehicle when
the world has none) and at twice it, and the stand moved on a grid of up to 10 cm in each
direction (no noise).

A run succeeds when the program ends normally having met the world's goal (vm/sim/goal.py);
in a world without a [goal], having reached the stand: it held the vehicle (`HLD`,
Listing 1's `:29`) with the camera within REACH cm of the stand's marker. "back" counts
the successes that also ended over the guidance line (the line named "guide" within half
the vehicle's width of its centre), where the paper says the vehicle returns.

    .venv/bin/python bench/robustness.py [--seeds N] [--program FILE.rob]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from collections.abc import Iterator
from itertools import pairwise
from pathlib import Path

import msgspec

from rl1.compiler.runner import Finished, run
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.geometry import segment_nearest
from rl1.vm.sim.world import NOISELESS, Noise, World, decode_world

ROOT = Path(__file__).parents[1]
WORLDS = ("sample.world.toml", "sample.mirrored.world.toml")
REACH = 80.0  # cm from the camera to the marker when the vehicle holds: "at the stand"
GRID = (-10, -5, 0, 5, 10)  # cm the stand is moved along x and along y


def outcome(program: str, world: World, seed: int) -> tuple[bool, bool]:
    """Whether the run succeeded, and whether it also ended over the guidance line."""
    device = SimDevice(world, seed=seed)
    judging = None if world.goal is None else world.judge(device.sim.pose)
    if judging is not None:
        device.sim.on_move = judging.step
    finished = run(program, device)
    if not isinstance(finished, Finished) or finished.result.fault is not None:
        return False, False
    device.run_on()  # as rl1c sim does: motion left in effect runs on
    vehicle = world.vehicle
    if judging is not None:
        reached = judging.verdict(device.sim.time).met
    else:
        marker = world.stands[0].marker()
        reached = False
        for entry in device.trace:
            if entry.call == "HLD":
                pose = entry.pose
                eye = (pose.x + vehicle.camera_ahead * math.cos(pose.heading),
                       pose.y + vehicle.camera_ahead * math.sin(pose.heading))
                reached = math.dist(eye, marker) <= REACH
    if not reached:
        return False, False
    pose = device.sim.pose
    guides = [line for line in world.lines if line.name == "guide"]
    back = any(segment_nearest(pose.x, pose.y, a, b)[2] <= vehicle.width / 2
               for line in guides for a, b in pairwise(line.points))
    return True, back


def scaled(noise: Noise, factor: float) -> Noise:
    """Every standard deviation of `noise` times `factor` (flags stay as they are)."""
    changes = {name: value * factor for name in noise.__struct_fields__
               if isinstance(value := getattr(noise, name), float)}
    return msgspec.structs.replace(noise, **changes)


def noise_of(world: World) -> Noise:
    """The world's noise, or the defaults when it has none."""
    return Noise() if world.noise == NOISELESS else world.noise


def moved(world: World, dx: float, dy: float) -> World:
    """`world` with its first stand, and the goal's holds at its marker, moved."""
    stand = world.stands[0]
    goal = world.goal
    if goal is not None:
        goal = dataclasses.replace(goal, holds=tuple(
            dataclasses.replace(hold, marker=(hold.marker[0] + dx, hold.marker[1] + dy))
            if hold.stand == stand.name else hold for hold in goal.holds))
    return dataclasses.replace(world, goal=goal, stands=(dataclasses.replace(
        stand, x=stand.x + dx, y=stand.y + dy), *world.stands[1:]))


def rate(program: str, world: World, seeds: int) -> tuple[int, int]:
    successes = backs = 0
    for seed in range(seeds):
        success, back = outcome(program, world, seed)
        successes += success
        backs += back
    return successes, backs


def _cells(program: str, world: World) -> Iterator[str]:
    quiet = dataclasses.replace(world, noise=NOISELESS)
    for dy in reversed(GRID):
        yield f"  y{dy:+3d} " + " ".join(
            {(True, True): "  B", (True, False): "  S", (False, False): "  ."}[
                outcome(program, moved(quiet, dx, dy), 0)] for dx in GRID)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=100)
    parser.add_argument("--program", type=Path, default=ROOT / "examples" / "sample.rob")
    options = parser.parse_args()
    program = options.program.read_text()
    print(f"Listing 1 ({options.program.name}), {options.seeds} seeds; success = ended "
          f"normally and met the world's goal (without one: held within {REACH:g} cm of the "
          "marker); back = and over the guidance line at the end")
    for name in WORLDS:
        world = decode_world((ROOT / "examples" / name).read_bytes(), name)
        stand = world.stands[0]
        noise = noise_of(world)
        print(f"\n{name}: stand at ({stand.x:g}, {stand.y:g}) facing {stand.facing:g}")
        quiet = outcome(program, dataclasses.replace(world, noise=NOISELESS), 0)
        print(f"  no noise: {'success' if quiet[0] else 'failure'}"
              f"{', back on the guidance line' if quiet[1] else ''}")
        print("  default noise: " + ", ".join(
            f"{field} {value:g}" for field in noise.__struct_fields__
            if isinstance(value := getattr(noise, field), float) and value))
        for factor, label in ((1, "default noise"), (2, "twice that")):
            successes, backs = rate(program, dataclasses.replace(
                world, noise=scaled(noise, factor)), options.seeds)
            print(f"  {label:13}: {successes:3d}/{options.seeds} succeed, {backs:3d} back")
        print("  the stand moved by dx (columns) and dy (rows), cm, no noise: "
              "B success and back, S success, . failure")
        print("       " + " ".join(f"{dx:+3d}" for dx in GRID))
        for row in _cells(program, world):
            print(row)


if __name__ == "__main__":
    main()
