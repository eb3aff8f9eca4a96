"""Sensor scripts of many line losses: decoding a script and running a program through
all of its losses, at 0.25 to 2 MB of script. The figure is the time per megabyte and
how it grows with size (x2 for twice the size is linear, x4 quadratic: the device was,
100 s at 20,000 losses). The program is a tracing loop, as a user's would be: it drives,
waits, reads the odometer and counts, so losses fall both into waits and between calls.

    .venv/bin/python bench/script_speed.py
"""

from __future__ import annotations

import argparse
import functools
import json

from timing import best_time

from rl1.compiler.runner import Finished
from rl1.compiler.runner import run as run_program
from rl1.vm.scripted import ScriptedDevice, decode_script

PROGRAM = """(TRC 1); N=50
:10 (MOV 3,3); (TIM 5); A=(KYO); N--
?N>#10
(MOV 0,0); (END)
"""


def script_of(losses: int) -> bytes:
    entries = [{"during": "MOV", "nth": 1 + i % 50, "after": 1 + i % 499} for i in range(losses)]
    entries += [{"time": 3 * i + 1} for i in range(losses)]
    return json.dumps({"line_lost": entries, "after_last": "repeat"}).encode()  # KYO reads 0


def run(data: bytes) -> None:
    device = ScriptedDevice(decode_script(data, "losses.json"))
    finished = run_program(PROGRAM, device)
    assert isinstance(finished, Finished) and finished.result.fault is None, finished


def main() -> None:
    argparse.ArgumentParser(description=__doc__.split("\n\n")[0]).parse_args()
    previous = None
    for losses in (2_500, 5_000, 10_000, 20_000):
        data = script_of(losses)
        seconds = best_time(functools.partial(run, data), 3)
        megabytes = len(data) / 2**20
        growth = "" if previous is None else f", x{seconds / previous:.2f} for twice the size"
        print(f"{2 * losses:>6} losses, {megabytes:.2f} MB: {seconds * 1000:7.1f} ms "
              f"({seconds / megabytes * 1000:.0f} ms per MB{growth})")
        previous = seconds


if __name__ == "__main__":
    main()
