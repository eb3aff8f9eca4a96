"""One run on the simulator, judged: what `rl1c sim` and a campaign of runs
(compiler/campaign.py) both do around the run stage (compiler/runner.py), written once
so that a campaign's run is the `rl1c sim --seed` run it names.

`Simulation` sets the simulated vehicle up in a world with a seed and, when the world
has a `[goal]`, the judge that watches every exact step; after the engine has run the
program on its `device`, `end` lets a vehicle left moving run on, notes how the run
ended, and judges it. `run_status` is how the run ended as JSON data (its exit status
the command's).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from rl1.vm.faults import RunResult
from rl1.vm.sim.device import RunOn, SimDevice
from rl1.vm.sim.goal import GOAL_MISSED, Verdict
from rl1.vm.sim.world import World


@dataclass(frozen=True, slots=True)
class Ending:
    """How a simulated run ended: the simulated time when the program ended (before any
    run-on), where the vehicle ran on to after an (END) that left it moving, and the
    goal's verdict (None when the world has no goal)."""

    ended_at: float
    run_on: RunOn | None
    verdict: Verdict | None


class Simulation:
    """The simulated vehicle in `world`, its noise drawn from `seed`, and the judge of
    the world's goal."""

    def __init__(self, world: World, seed: int) -> None:
        self.device = SimDevice(world, seed=seed)
        self._judge = None if world.goal is None else world.judge(self.device.sim.pose)
        if self._judge is not None:
            self.device.sim.on_move = self._judge.step  # each exact step: the track is decimated

    def end(self, result: RunResult) -> Ending:
        """After the engine ran the program to `result`: the run-on, the closing note of
        the record, and the verdict."""
        device = self.device
        ended_at = device.sim.time
        run_on = None
        if result.fault is None:
            moving = device.sim.motion is not None
            device.sim.note("end", "the program ended" + (
                " with the vehicle moving: it runs on" if moving else ""))
            run_on = device.run_on()  # (END) leaves motion in effect: where does it go?
        elif device.fault is None:  # a safety stop has noted itself
            device.sim.note("fault", result.fault.message)
        verdict = None if self._judge is None else self._judge.verdict(device.sim.time)
        return Ending(ended_at, run_on, verdict)


def run_status(result: RunResult, verdict: Verdict | None) -> dict[str, Any]:
    """How the run ended, as `rl1c run`'s status (its exit status the command's), but
    a program that ended without meeting the world's goal is `goal-missed` (a fault
    comes first: the goal is judged all the same, and reported beside it)."""
    if result.fault is not None or verdict is None or verdict.met:
        return result.status()
    return {"code": "goal-missed", "exit_status": GOAL_MISSED,
            "message": f"the program ended, but {verdict.headline()}", "line": None}
