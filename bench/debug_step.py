"""The debugging core's cost (compiler/debugger.py): Listing 1 on the scene of Fig. 4
(examples/sample.world.toml) run to its end by `runner.run` (the reference) and by a
session's continue with a breakpoint that never holds, as a ratio; and the time a line
step takes, stepping the whole run line by line (median and slowest), against issue 28's
goal of 20 ms a step.

CPU time (time.process_time), the fastest of RUNS runs: the machine is shared.

    .venv/bin/python bench/debug_step.py
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

from rl1.compiler.debugger import Session, compile_program
from rl1.compiler.runner import run
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.world import decode_world

ROOT = Path(__file__).parents[1]
SAMPLE = (ROOT / "examples" / "sample.rob").read_text()
WORLD = decode_world((ROOT / "examples" / "sample.world.toml").read_bytes(), "sample.world.toml")
RUNS = 5
GOAL_MS = 20.0


def _session() -> Session:
    image = compile_program(SAMPLE, "sample.rob")
    assert isinstance(image, bytes)
    return Session(image, lambda: SimDevice(WORLD))


def whole_run() -> float:
    started = time.process_time()
    run(SAMPLE, SimDevice(WORLD))
    return time.process_time() - started


def continued() -> float:
    session = _session()
    session.set_line_breakpoints([(22, "y-32767>0")])  # checked at every entry, never met
    started = time.process_time()
    while not session.over:
        session.continue_()
    return time.process_time() - started


def line_steps() -> list[float]:
    session = _session()
    steps = []
    while not session.over:
        started = time.process_time()
        session.step_line()
        steps.append(time.process_time() - started)
    return steps


def main() -> None:
    reference = min(whole_run() for _ in range(RUNS))
    debugged = min(continued() for _ in range(RUNS))
    print(f"Listing 1 on the sample world, to its end: runner.run {reference * 1000:.1f} ms, "
          f"a session's continue {debugged * 1000:.1f} ms ({debugged / reference:.2f}x)")
    steps = min((line_steps() for _ in range(RUNS)), key=sum)
    median, slowest = statistics.median(steps) * 1000, max(steps) * 1000
    print(f"line steps: {len(steps)}, median {median:.3f} ms, slowest {slowest:.3f} ms "
          f"(goal {GOAL_MS:g} ms: {'met' if slowest <= GOAL_MS else 'missed'})")


if __name__ == "__main__":
    main()
