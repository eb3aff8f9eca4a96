"""The studio's server as a page meets it (spec/studio.md; issue 28's goals): the wall
time from a `debug/stepLine` request to its `run/stopped` over the WebSocket, stepping
Listing 1 on the sample world line by line (median and slowest, goal 20 ms), against the
same steps of the debugging core's Session alone in this process; and the frames a
second of a live run at 10x real time (goal 30), with how far the simulated time kept
to ten times the wall time; and a whole run at full speed, from run/launch to run/ended,
against a Session's continue alone.

The server runs in a thread of this process, on a free port of 127.0.0.1 (as the tests
serve it: tests/studio/served.py); wall time (time.perf_counter), as the page sees it.
The machine is shared: the figures vary.

    .venv/bin/python bench/studio_step.py
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any

from websockets.sync.client import ClientConnection, connect

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "studio")]

from debug_step import line_steps, listing_1_session  # noqa: E402  (bench/ is this script's folder)
from served import serving  # noqa: E402  (tests/ on the path just above)
from support import EXAMPLES  # noqa: E402

STEP_GOAL_MS = 20.0
FRAMES_GOAL = 30
LIVE_SECONDS = 4.0
SPEED = 10
RUNS = 3  # the fastest of these: the machine is shared


class Page:
    def __init__(self, connection: ClientConnection) -> None:
        self.connection = connection
        self.id = 0

    def request(self, method: str, params: dict[str, Any] | None = None) -> None:
        self.id += 1
        self.connection.send(json.dumps({"jsonrpc": "2.0", "id": self.id, "method": method,
                                         "params": params or {}}))

    def until(self, *methods: str) -> tuple[str, dict[str, Any]]:
        while True:
            message = json.loads(self.connection.recv(timeout=60))
            if message.get("method") in methods:
                return message["method"], message["params"]
            if "error" in message:
                raise RuntimeError(message["error"]["message"])


def launch(page: Page, **options: Any) -> None:
    page.request("run/launch", {"program": {"path": "sample.rob"},
                                "world": {"path": "sample.world.toml"}, **options})


def server_steps(page: Page) -> list[float]:
    """Each line step of the whole run, from the request to its answer's stop."""
    launch(page, stopOnEntry=True)
    page.until("run/stopped")
    steps = []
    while True:
        started = time.perf_counter()
        page.request("debug/stepLine")
        method, _ = page.until("run/stopped", "run/ended")
        steps.append(time.perf_counter() - started)
        if method == "run/ended":
            return steps


def whole_run(page: Page) -> float:
    """From run/launch at full speed to run/ended: the run, its frames and its trace."""
    started = time.perf_counter()
    launch(page, speed=None)
    page.until("run/ended")
    return time.perf_counter() - started


def session_run() -> float:
    """The same run by a Session's continue alone."""
    session = listing_1_session()
    started = time.perf_counter()
    while not session.over:
        session.continue_()
    return time.perf_counter() - started


def live(page: Page) -> tuple[int, float, float]:
    """Frames received in LIVE_SECONDS of a run at SPEED, the wall time, and the
    simulated time reached."""
    launch(page, speed=SPEED)
    page.until("run/frame")
    started = time.perf_counter()  # from the first frame: the launch is not counted
    frames, simulated = 0, 0.0
    while (elapsed := time.perf_counter() - started) < LIVE_SECONDS:
        method, params = page.until("run/frame", "run/ended")
        if method == "run/ended":
            break
        frames += 1
        simulated = params["frame"]["time"]
    page.request("debug/stop")
    page.until("run/ended")
    return frames, elapsed, simulated


def main() -> None:
    argparse.ArgumentParser(description=__doc__.split("\n\n")[0]).parse_args()
    alone = line_steps(time.perf_counter)  # the same steps of a Session alone
    reference = min(session_run() for _ in range(RUNS))
    with serving(EXAMPLES) as served, connect(served.url("/studio", scheme="ws"),
                                              max_size=None) as connection:
        page = Page(connection)
        steps = server_steps(page)
        whole = min(whole_run(page) for _ in range(RUNS))
        frames, elapsed, simulated = live(page)
    median, slowest = statistics.median(steps) * 1000, max(steps) * 1000
    print(f"line steps of Listing 1 on the sample world: {len(steps)}, request to "
          f"run/stopped median {median:.2f} ms, slowest {slowest:.2f} ms (goal "
          f"{STEP_GOAL_MS:g} ms: {'met' if median <= STEP_GOAL_MS else 'missed'}); the "
          f"Session alone: median {statistics.median(alone) * 1000:.3f} ms, slowest "
          f"{max(alone) * 1000:.2f} ms")
    print(f"the whole run at full speed: run/launch to run/ended {whole * 1000:.0f} ms, a "
          f"Session's continue alone {reference * 1000:.0f} ms ({whole / reference:.2f}x)")
    rate = frames / elapsed
    kept = frames >= FRAMES_GOAL * elapsed - 1  # one frame: where the window cuts the grid
    print(f"live at {SPEED}x real time: {frames} frames in {elapsed:.2f} s, {rate:.1f} a "
          f"second (goal {FRAMES_GOAL}: {'met' if kept else 'missed'}); "
          f"simulated {simulated:.2f} s, {simulated / elapsed:.2f}x the wall time")


if __name__ == "__main__":
    main()
