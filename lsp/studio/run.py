"""One launched program of a studio connection: the debugging core's Session
(compiler/debugger.py) in a worker thread of its own, so that the page stays live and
`pause` reaches it; on a world, paced to a speed and shown in frames (spec/studio.md).

The worker carries out one command at a time (start, continue, a step, restart) and
tells how it ended, a `run/stopped` or `run/ended` notification. Continuing is a line
step after another until one stops for a reason of its own (a breakpoint, a call, a
lost line, a pause, the end): the same stops as the Session's `continue_`, with a point
between two lines where the run is paced and a frame may be sent. Within a line, the
simulator's `on_move` (each exact step of the vehicle, a few per simulated tenth of a
second) paces and frames the long calls, an (MVI) or a (TIM) while moving. The pacing
sleeps on an event that a pause, a restart or a new speed sets, so none waits for it.

Everything the worker reads of the run, it owns; the event loop reads the session only
while no command is under way, and hears of the worker through
`loop.call_soon_threadsafe`. A command a restart or a new launch overtook (its
generation is no longer the run's) is dropped, and so is what it would have told.
"""

from __future__ import annotations

import asyncio
import logging
import math
import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

from rl1.compiler.debugger import Session, Stop
from rl1.compiler.simulation import Simulation, run_status
from rl1.vm.defaults import DEFAULT_TIME_LIMIT_MS
from rl1.vm.device import Device
from rl1.vm.language import VARIABLES
from rl1.vm.scripted import ScriptedDevice, TraceEntry
from rl1.vm.sensor_script import Script
from rl1.vm.sim.device import SimDevice, SimEntry
from rl1.vm.sim.motion import Pose, heading_degrees
from rl1.vm.sim.render import describe_call
from rl1.vm.sim.sightings import SightingImages
from rl1.vm.sim.simulator import Event, Simulator
from rl1.vm.sim.world import World

log = logging.getLogger(__name__)

Command = Literal["start", "continue", "stepLine", "stepInstruction", "restart"]
Tell = Callable[[str, dict[str, Any]], bool]
"""Sends a notification to the page; False when it was dropped (a `run/frame` to a page
that has fallen behind)."""

FRAMES_PER_SECOND = 30
"""The most `run/frame`s a second of wall time."""
DEFAULT_SPEED = 1.0
MIN_SPEED, MAX_SPEED = 0.1, 1000.0
_FRAME_INTERVAL = 1 / FRAMES_PER_SECOND
_BEHIND = 0.25
"""Seconds of wall time the run may fall behind its pace (a slow machine, a long
computation) before the pace starts again from where the run is, rather than hurrying
to catch up."""


@dataclass(frozen=True, slots=True)
class Launch:
    """What a run needs: the program's `.ilc` image, and a world (with the seed of its
    noise) or a sensor script (None: no script), and the watchdog's budget."""

    image: bytes
    world: World | None
    script: Script | None
    seed: int
    budget: int
    stop_on_entry: bool


class Run:
    """A launched program, commanded from the event loop `loop`; what it tells goes to
    `tell` on that loop."""

    def __init__(self, launch: Launch, tell: Tell, loop: asyncio.AbstractEventLoop,
                 speed: float | None) -> None:
        self._launch = launch
        self._tell = tell
        self._loop = loop
        self._speed = speed
        self._simulation: Simulation | None = None
        self._generation = 0  # the run's now: a command of an older one is dropped
        self._current = 0  # the generation of the command the worker carries out
        self._commands: queue.Queue[tuple[int, Command] | None] = queue.Queue()
        self._pausing = threading.Event()  # the command under way is to stop
        self._wake = threading.Event()  # a pacing sleep is to end
        self._pacing = False  # a continue is under way (steps are not slowed)
        self._anchor = (0.0, 0.0)  # the wall time and simulated time the pace is kept from
        self._next_frame = -math.inf  # when the next frame is due (time.monotonic)
        self._told_trace = self._told_events = 0
        # What a dropped frame carried, and its generation (the loop's, like `busy`).
        self._held: tuple[int, dict[str, Any]] | None = None
        # The (IMG)s counted when an image was last told, in any notification, in a stop.
        self._imaged = self._imaged_at_stop = 0
        self._images = None if launch.world is None else SightingImages(launch.world)
        self._seen: dict[str, int] = {}
        self.busy = False  # a command is under way (the loop's view)
        self.over = False  # the run has ended (the loop's view)
        self.session = Session(launch.image, self._new_device, launch.budget)
        self._started()
        self._worker = threading.Thread(target=self._work, name="rl1c studio run",
                                        daemon=True)
        self._worker.start()

    # Commands, from the event loop

    def command(self, command: Command) -> None:
        """Start `command`; the run is busy until it has told how it ended."""
        if command == "restart":
            self._interrupt()
        self.busy = True
        self._pausing.clear()
        self._commands.put((self._generation, command))

    def pause(self) -> None:
        """Stop the command under way at its next instruction."""
        self._pausing.set()
        self.session.pause()
        self._wake.set()

    def set_speed(self, speed: float | None) -> None:
        self._speed = speed
        self._anchor = (time.monotonic(), self._sim_time())
        self._wake.set()

    def close(self) -> None:
        """Drop the run: the command under way stops, and nothing more is told."""
        self._interrupt()
        self._commands.put(None)

    def _interrupt(self) -> None:
        self._generation += 1
        self.pause()

    # The worker

    def _work(self) -> None:
        while (item := self._commands.get()) is not None:
            generation, command = item
            if generation != self._generation:
                continue
            self._current = generation
            try:
                method, params = self._carry_out(command)
            except Exception as error:  # a bug of ours: the page hears of it
                log.exception("rl1c studio: the run failed")
                method, params = "run/ended", {"status": {
                    "code": "internal-error", "exit_status": 3, "line": None,
                    "message": f"rl1c studio failed ({error!r}): please report it"}}
            self._loop.call_soon_threadsafe(self._finished, generation, method, params)

    def _finished(self, generation: int, method: str, params: dict[str, Any]) -> None:
        if generation != self._generation:
            return
        self.busy = False
        self.over = method == "run/ended"
        self._send(generation, method, params)

    def _carry_out(self, command: Command) -> tuple[str, dict[str, Any]]:
        session = self.session
        if command == "restart":
            session.restart()
            self._started()
        if command in ("start", "restart"):
            stop = (Stop("entry", session.line) if self._launch.stop_on_entry
                    else self._continue())
        elif command == "continue":
            stop = self._continue()
        elif command == "stepLine":
            stop = session.step_line()
        else:
            stop = session.step_instruction()
        if session.over:
            return "run/ended", self._ended()
        return "run/stopped", self._stopped(stop)

    def _stopping(self) -> bool:
        """Whether the command under way is to stop: paused, or overtaken."""
        return self._pausing.is_set() or self._current != self._generation

    def _continue(self) -> Stop:
        """Line steps until one stops for a reason of its own, paced."""
        session = self.session
        self._anchor = (time.monotonic(), self._sim_time())
        self._pacing = True
        try:
            while True:
                if self._stopping():
                    return Stop("pause", session.line, "paused")
                stop = session.step_line()
                if stop.reason != "step":
                    return stop
                self._pace()
        finally:
            self._pacing = False

    def _pace(self) -> None:
        """Wait until the wall clock catches up with the simulated time at the speed,
        sending the frames that fall due meanwhile."""
        simulation, speed = self._simulation, self._speed
        if simulation is None:
            return
        now = time.monotonic()
        if speed is not None:
            wall, simulated = self._anchor
            due = wall + (simulation.device.sim.time - simulated) / speed
            while now < due and not self._stopping() and not self._wake.is_set():
                self._frame_if_due(now)
                self._wake.wait(min(due, self._next_frame) - now)
                now = time.monotonic()
            self._wake.clear()
            if now - due > _BEHIND:
                self._anchor = (now, simulation.device.sim.time)
        self._frame_if_due(now)

    def _frame_if_due(self, now: float) -> None:
        """A frame, when the next is due: on a grid of 1/FRAMES_PER_SECOND, so that the
        frames keep their rate however the chances to send one fall."""
        if now < self._next_frame:
            return
        self._next_frame += _FRAME_INTERVAL
        if self._next_frame <= now:  # late by a whole frame or more: no burst to catch up
            self._next_frame = now + _FRAME_INTERVAL
        params = {"frame": self._frame_now(), **self._news()}
        self._loop.call_soon_threadsafe(self._deliver, self._current, "run/frame", params)

    def _deliver(self, generation: int, method: str, params: dict[str, Any]) -> None:
        if generation == self._generation:
            self._send(generation, method, params)

    def _send(self, generation: int, method: str, params: dict[str, Any]) -> None:
        """Tell the page, on the loop. What a dropped frame carried (trace entries,
        events, an image) goes in the next notification of the same run instead, so the
        page's trace misses nothing."""
        held, self._held = self._held, None
        if held is not None and held[0] == generation and "trace" in params:
            # Extended, not added: a page behind for long drops many frames in a row,
            # and copying what they held at each would grow as its square.
            before = held[1]
            before["trace"].extend(params["trace"])
            before["events"].extend(params["events"])
            params = {**params, "trace": before["trace"], "events": before["events"],
                      "image": params["image"] or before["image"]}
        if not self._tell(method, params):
            self._held = generation, params

    # The device

    def _new_device(self) -> Device:
        launch = self._launch
        if launch.world is None:
            self._simulation = None
            return ScriptedDevice(launch.script, DEFAULT_TIME_LIMIT_MS)  # rl1c run's
        simulation = self._simulation = Simulation(launch.world, launch.seed)
        sim = simulation.device.sim
        judge = sim.on_move

        def moved(start: float, end: float, before: Pose, after: Pose) -> None:
            if judge is not None:
                judge(start, end, before, after)
            if self._pacing:
                self._pace()

        sim.on_move = moved
        return simulation.device

    def _sim_time(self) -> float:
        return 0.0 if self._simulation is None else self._simulation.device.sim.time

    # What the page is told

    def _started(self) -> None:
        """A start of the run (the launch, a restart): nothing told of it yet."""
        self._told_trace = self._told_events = 0
        self._imaged = self._imaged_at_stop = 0
        self._seen = self.session.variables
        self._next_frame = -math.inf

    def _stopped(self, stop: Stop) -> dict[str, Any]:
        variables = self.session.variables
        changed = [name for name in VARIABLES if variables[name] != self._seen[name]]
        self._seen = variables
        return {"reason": stop.reason, "line": stop.line, "text": stop.text,
                "variables": variables, "changed": changed,
                "device": self.session.device_state(), "frame": self._frame_now(),
                **self._news(stop=True)}

    def _ended(self) -> dict[str, Any]:
        session = self.session
        result = session.result
        assert result is not None
        device = session.device
        verdict = None
        if self._simulation is not None:
            ending = self._simulation.end(result)
            verdict, device_time = ending.verdict, round(ending.ended_at * 1000)
        else:
            assert isinstance(device, ScriptedDevice)
            device_time = device.time
        status = run_status(result, verdict)
        if isinstance(device, SimDevice) and device.fault is not None:
            status |= {"safety": device.fault.kind, "time": round(device.fault.time, 4),
                       "pose": pose_json(device.fault.pose)}
        return {"status": status, "variables": result.named(),
                "instructions": session.machine.executed, "deviceTime": device_time,
                "goal": None if verdict is None else verdict.to_json(),
                "frame": self._frame_now(), **self._news(stop=True)}

    def _frame_now(self) -> dict[str, Any] | None:
        if self._simulation is None:
            return None
        return frame(self._simulation.device.sim, self.session.line)

    def _news(self, stop: bool = False) -> dict[str, Any]:
        """The trace entries and events since the last told, and the last (IMG)'s image
        when one came since then (in a stop: since the last stop, so that a frame the
        connection dropped loses none the page keeps)."""
        trace = self.session.trace
        new_trace = trace[self._told_trace:]
        self._told_trace = len(trace)
        events: list[Event] = []
        if self._simulation is not None:
            recorded = self._simulation.device.sim.events
            events = recorded[self._told_events:]
            self._told_events = len(recorded)
        return {"trace": [trace_entry(entry) for entry in new_trace],
                "events": [event_json(event) for event in events],
                "image": self._new_image(stop)}

    def _new_image(self, stop: bool) -> dict[str, Any] | None:
        if self._simulation is None or self._images is None:
            return None
        sightings = self._simulation.device.sightings
        if sightings.added == (self._imaged_at_stop if stop else self._imaged):
            return None
        self._imaged = sightings.added
        if stop:
            self._imaged_at_stop = sightings.added
        latest = sightings.latest
        assert latest is not None
        return self._images.encoded(latest)


def pose_json(pose: Pose) -> list[float]:
    return [round(pose.x, 2), round(pose.y, 2), heading_degrees(pose.heading, 2)]


def frame(sim: Simulator, line: int | None) -> dict[str, Any]:
    """The vehicle now (spec/studio.md, Frame)."""
    return {"time": round(sim.time, 4), "line": line, "pose": pose_json(sim.pose),
            "wheels": [round(speed, 3) for speed in sim.wheel_speeds],
            "steering": round(math.degrees(sim.steering), 2), "pan": sim.pan,
            "tilt": "down" if sim.tilted_down else "up", "mode": sim.mode,
            "scene": sim.scene}


def trace_entry(entry: TraceEntry | SimEntry) -> dict[str, Any]:
    """A call the device received (spec/studio.md, TraceEntry)."""
    match entry:
        case SimEntry():
            return {**entry.to_json(), "text": describe_call(entry)}
        case TraceEntry():
            shown: dict[str, Any] = {"time": entry.time / 1000, "call": entry.call,
                                     "args": list(entry.args), "line": entry.line,
                                     "text": entry.describe()}
            if entry.result is not None:
                shown["result"] = list(entry.result)
            return shown


def event_json(event: Event) -> dict[str, Any]:
    return {"time": round(event.time, 4), "kind": event.kind, "text": event.text,
            "pose": [round(event.pose.x, 2), round(event.pose.y, 2)]}
