"""The simulator's speed: simulated seconds per CPU second on Listing 1 (the
scene of Fig. 4), on examples/fig4.rob in its scene (which runs its course with noise
on, where Listing 1 as printed faults within seconds) and on a ten-minute patrol
(tracing a round track, reading the ultrasonic sensor, the odometer and a small image
window once a second), against the goal of 1000x real time, each without noise and
with the default noise (seed 0); and the cost of one (IMG) on a full 256 x 240 image
and on Listing 1's 60 x 6 window.

The machine is shared: CPU time (time.process_time) is counted rather than wall-clock
time, which other processes stretch, and each figure is the fastest of RUNS runs. The
programs are compiled before the clock starts: it times the simulated run alone.

    .venv/bin/python bench/sim_speed.py
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.runner import Finished, run
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.world import NOISELESS, Noise, Scene, World, decode_world

ROOT = Path(__file__).parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from support.worlds import round_track  # noqa: E402  (tests/ is put on the path just above)

SAMPLE = (ROOT / "examples" / "sample.rob").read_text()
WORLD = decode_world((ROOT / "examples" / "sample.world.toml").read_bytes(), "sample.world.toml")
# The robust scene (spec/simulator.md, "The paper's reading"): with noise on, Listing 1 as
# printed faults within seconds on the sample world, while this program runs its course.
FIG4 = (ROOT / "examples" / "fig4.rob").read_text()
FIG4_WORLD = replace(decode_world((ROOT / "examples" / "fig4.world.toml").read_bytes(),
                                  "fig4.world.toml"), noise=NOISELESS)

PATROL = """'PATROL: trace the round track for ten minutes, looking ahead once a second
(CAM A 90); (CAM D); (SCN 0); (TRC 1); (KYC)
N=600
:10 (MOV 4,4); (TIM 10); A=(ULT A); B=(KYO); C=(IMG); N--
?N>#10
(MOV 0,0); (FRE); (END)
"""


RUNS = 7


def simulate(code: bytes, world: World) -> tuple[float, float, str]:
    """Simulated and CPU seconds of one run of the compiled `code`, and how it ended
    when not normally (noise may make a run fault: its speed is still what it is)."""
    device = SimDevice(world)
    gc.collect()
    started = time.process_time()
    finished = run(code, device)
    cpu = time.process_time() - started
    assert isinstance(finished, Finished), finished
    fault = finished.result.fault
    assert fault is None or world.noise != NOISELESS, fault  # exact runs end normally
    return device.sim.time, cpu, "" if fault is None else f" (ended on a fault: {fault.kind.code})"


def cpu_time(action: Callable[[], object], repeats: int) -> float:
    """The least CPU time of `repeats` calls of `action`."""
    times = []
    for _ in range(repeats):
        started = time.process_time()
        action()
        times.append(time.process_time() - started)
    return min(times)


def image_cost(window: tuple[int, int, int, int]) -> float:
    world = World(floor=WORLD.floor, start=WORLD.start, lines=WORLD.lines, marks=WORLD.marks,
                  stands=WORLD.stands, scenes={0: Scene(("lines", "marks", "markers"), window)})
    device = SimDevice(world)
    device.camera_down()
    return cpu_time(device.sim.image, 200)


def main() -> None:
    argparse.ArgumentParser(description=__doc__.split("\n\n")[0]).parse_args()
    for name, text, world in (("Listing 1, Fig. 4", SAMPLE, WORLD),
                              ("fig4.rob, its scene", FIG4, FIG4_WORLD),
                              ("ten-minute patrol", PATROL, round_track())):
        code = compile_text(text, "bench.rob").output
        assert code is not None
        for noise, noisy in (("no noise", world), ("noise on", replace(world, noise=Noise()))):
            runs = [simulate(code, noisy) for _ in range(RUNS)]
            simulated, cpu, ending = min(runs, key=lambda run: run[1])
            print(f"{name}, {noise}: {simulated:7.1f} s simulated in {cpu:6.3f} s of CPU: "
                  f"{simulated / cpu:7.0f}x real time{ending}")
    full = image_cost((0, 0, 256, 240))
    small = image_cost((98, 117, 158, 123))
    print(f"one IMG: {full * 1000:.2f} ms on the full 256 x 240 image, "
          f"{small * 1000:.3f} ms on a 60 x 6 window")


if __name__ == "__main__":
    main()
