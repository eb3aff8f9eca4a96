"""The debugging core's cost (compiler/debugger.py): Listing 1 on the scene of Fig. 4
(examples/sample.world.toml) run to its end by `runner.run` (the reference) and by a
session's continue with a breakpoint that never holds, as a ratio; and the time a line
step takes, stepping the whole run line by line (median and slowest), against issue 28's
goal of 20 ms a step. Then breakpoints at scale: an rl1-dap `setBreakpoints` request
(lsp/dap.py's Adapter, in this process) of 10,000 conditional breakpoints, one a line of
a program of 10,000 lines, against compiling that program; the same request again with
one condition changed (as a client sends the whole list at each edit); and a continue
over that program with the 10,000 breakpoints set, never met, against one with none.

CPU time (time.process_time), the fastest of RUNS runs: the machine is shared.

    .venv/bin/python bench/debug_step.py
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rl1.compiler.debugger import Session, compile_program
from rl1.compiler.runner import run
from rl1.lsp.dap import Adapter
from rl1.vm.scripted import ScriptedDevice
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.world import decode_world

ROOT = Path(__file__).parents[1]
SAMPLE = (ROOT / "examples" / "sample.rob").read_text()
WORLD = decode_world((ROOT / "examples" / "sample.world.toml").read_bytes(), "sample.world.toml")
RUNS = 5
GOAL_MS = 20.0
BREAKPOINTS = 10_000
LONG = "A=B\n" * BREAKPOINTS  # code on each line at -O0, in the 64 KiB of a program
NEVER_MET: list[dict[str, Any]] = [{"line": line, "condition": f"B-A-{line}>0"}
                                   for line in range(1, BREAKPOINTS + 1)]  # B=A=0 throughout


def listing_1_session() -> Session:
    """A debugging session of Listing 1 on the sample world, not yet begun."""
    image = compile_program(SAMPLE, "sample.rob")
    assert isinstance(image, bytes)
    return Session(image, lambda: SimDevice(WORLD))


def whole_run() -> float:
    started = time.process_time()
    run(SAMPLE, SimDevice(WORLD))
    return time.process_time() - started


def continued() -> float:
    session = listing_1_session()
    session.set_line_breakpoints([(22, "y-32767>0")])  # checked at every entry, never met
    started = time.process_time()
    while not session.over:
        session.continue_()
    return time.process_time() - started


def line_steps(clock: Callable[[], float] = time.process_time) -> list[float]:
    """The time of each line step of Listing 1's whole run on the sample world, by
    `clock` (bench/studio_step.py's reference takes wall time, as a page sees it)."""
    session = listing_1_session()
    steps = []
    while not session.over:
        started = clock()
        session.step_line()
        steps.append(clock() - started)
    return steps


class Client:
    """rl1-dap's Adapter in this process, each message it sends encoded as its `serve`
    encodes it, and the last response kept."""

    def __init__(self) -> None:
        self.adapter = Adapter(self._sent)
        self.response: dict[str, Any] = {}

    def _sent(self, message: dict[str, Any]) -> None:
        json.dumps(message, separators=(",", ":")).encode("utf-8")
        if message["type"] == "response":
            self.response = message

    def request(self, command: str, arguments: dict[str, Any]) -> float:
        """The CPU time of one request, which must succeed."""
        body = json.dumps({"seq": 1, "type": "request", "command": command,
                           "arguments": arguments}).encode()
        started = time.process_time()
        self.adapter.receive(body)
        elapsed = time.process_time() - started
        assert self.response["success"], self.response
        return elapsed


def set_breakpoints() -> tuple[float, float, float]:
    """rl1-dap's setBreakpoints of BREAKPOINTS conditions, then the same with one
    changed, and compiling the program they are set in (the reference)."""
    with tempfile.TemporaryDirectory(prefix="rl1-bench-") as folder:
        program = Path(folder) / "long.rob"
        program.write_text(LONG, encoding="utf-8")
        client = Client()
        client.request("launch", {"program": str(program), "level": 0})
        source = {"path": str(program)}
        first = client.request("setBreakpoints", {"source": source, "breakpoints": NEVER_MET})
        edited = [*NEVER_MET[:-1], {"line": BREAKPOINTS, "condition": "B-A>0"}]
        again = client.request("setBreakpoints", {"source": source, "breakpoints": edited})
    started = time.process_time()
    compile_program(LONG, "long.rob", 0)
    return first, again, time.process_time() - started


def continued_over_long(breakpoints: int) -> float:
    """A continue over LONG to its end, with the first `breakpoints` of NEVER_MET set."""
    image = compile_program(LONG, "long.rob", 0)
    assert isinstance(image, bytes)
    session = Session(image, lambda: ScriptedDevice(None))
    session.set_line_breakpoints((wanted["line"], wanted["condition"])
                                 for wanted in NEVER_MET[:breakpoints])
    started = time.process_time()
    assert session.continue_().reason == "end"
    return time.process_time() - started


def main() -> None:
    argparse.ArgumentParser(description=__doc__.split("\n\n")[0]).parse_args()
    reference = min(whole_run() for _ in range(RUNS))
    debugged = min(continued() for _ in range(RUNS))
    print(f"Listing 1 on the sample world, to its end: runner.run {reference * 1000:.1f} ms, "
          f"a session's continue {debugged * 1000:.1f} ms ({debugged / reference:.2f}x)")
    steps = min((line_steps() for _ in range(RUNS)), key=sum)
    median, slowest = statistics.median(steps) * 1000, max(steps) * 1000
    print(f"line steps: {len(steps)}, median {median:.3f} ms, slowest {slowest:.3f} ms "
          f"(goal {GOAL_MS:g} ms: {'met' if slowest <= GOAL_MS else 'missed'})")
    first, again, compiling = min((set_breakpoints() for _ in range(RUNS)), key=sum)
    print(f"rl1-dap setBreakpoints of {BREAKPOINTS:,} conditions, one a line of "
          f"{BREAKPOINTS:,}: {first * 1000:.1f} ms ({first / compiling:.2f}x compiling the "
          f"program, {compiling * 1000:.1f} ms); again with one changed "
          f"{again * 1000:.1f} ms ({again / compiling:.2f}x)")
    bare = min(continued_over_long(0) for _ in range(RUNS))
    watched = min(continued_over_long(BREAKPOINTS) for _ in range(RUNS))
    print(f"a continue over those {BREAKPOINTS:,} lines: {bare * 1000:.1f} ms without "
          f"breakpoints, {watched * 1000:.1f} ms with the {BREAKPOINTS:,} never met "
          f"({watched / bare:.2f}x)")


if __name__ == "__main__":
    main()
