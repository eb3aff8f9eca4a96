"""Each kind of stop of the debugging core, with what the run holds there worked out by
hand: Listing 1 (examples/sample.rob) on its sensor script (examples/sample.sensors.json)
and on the sample world, and small programs for lost lines, faults and stepping."""

from __future__ import annotations

import threading
from collections.abc import Callable

from support import SAMPLE, SAMPLE_SENSORS

from rl1.compiler.debugger import Session, Stop, compile_program
from rl1.compiler.runner import Finished, load_script, run
from rl1.vm.device import Device
from rl1.vm.faults import FaultKind
from rl1.vm.scripted import LOST, ScriptedDevice
from rl1.vm.sensor_script import parse_script
from rl1.vm.sim.device import SimDevice, SimEntry
from rl1.vm.sim.world import decode_world

LISTING_1 = SAMPLE.read_text(encoding="utf-8")
SCRIPT = load_script(SAMPLE_SENSORS)


def _session(text: str, make_device: Callable[[], Device] = lambda: ScriptedDevice(SCRIPT),
             budget: int = 100_000) -> Session:
    image = compile_program(text, "program.rob")
    assert isinstance(image, bytes), image
    return Session(image, make_device, budget)


def _nonzero(session: Session) -> dict[str, int]:
    return {name: value for name, value in session.variables.items() if value}


def test_a_breakpoint_on_line_20_of_listing_1_stops_there_with_the_runs_variables() -> None:
    session = _session(LISTING_1)
    (binding,) = session.set_line_breakpoints([(20, None)])
    assert (binding.line, binding.verified) == (20, True)
    assert session.continue_() == Stop("breakpoint", 20)
    # By hand, from the script: the mark's area reaches 185 (line 4); scene 4 sees the
    # stand at x=100 (L), scene 3 at x=160 (U); A=U-L=60>0 takes :12, c=579, d=450,
    # C=c, D=d; the five readings x=145, 140, 128, 128, 128 give a=17, 12, 0, 0, 0, so
    # C grows by (17<3+(17<4+17))>6 = 425>>6 = 6 and by 300>>6 = 4, and d, whose a<3+c
    # is shifted right by a then back, is 0 each time; @ counts down to 0.
    assert _nonzero(session) == {"A": 60, "L": 100, "U": 160, "C": 589, "D": 450,
                                 "w": 40, "x": 128, "y": 100}
    assert session.device_state() == {"time (ms)": 2000, "tracing mode": 0, "motion": None,
                                      "last readings": {"IMG": [40, 128, 100, 0]}}
    assert [entry.call for entry in session.trace].count("IMG") == 10


def test_a_conditional_breakpoint_stops_the_first_time_its_condition_holds() -> None:
    session = _session(LISTING_1)
    session.set_line_breakpoints([(22, "y-150>0")])
    # The approach reads y = 110, 125, 140, 155: line 22 is entered four times.
    assert session.continue_() == Stop("breakpoint", 22, "y-150>0")
    assert (session.variables["y"], session.variables["x"]) == (155, 128)
    assert session.variables["Y"] == 140 - 160  # the last time line 22 ran


def test_a_breakpoint_on_a_line_without_code_stops_on_the_next_line_with_code() -> None:
    session = _session(LISTING_1)
    bindings = session.set_line_breakpoints([(1, None), (11, "A>0"), (99, None)])
    assert [(b.requested, b.line) for b in bindings] == [(1, 2), (11, 12), (99, None)]
    assert bindings[2].message == "no code runs on this line or after it"
    assert session.continue_() == Stop("breakpoint", 2)  # before the first instruction
    assert session.machine.executed == 0
    assert session.continue_() == Stop("breakpoint", 12, "A>0")


def test_a_refused_condition_leaves_its_breakpoint_unverified_with_why() -> None:
    session = _session(LISTING_1)
    (binding,) = session.set_line_breakpoints([(20, "A<5")])
    assert not binding.verified
    assert "write `A-5<0`" in binding.message
    assert session.line_breakpoints == {}


def test_a_call_breakpoint_stops_before_each_call_of_that_built_in() -> None:
    session = _session(LISTING_1)
    session.set_call_breakpoints(["IMG"])
    stops = []
    while (stop := session.continue_()).reason == "call":
        stops.append((stop, len(session.trace)))  # the calls made before it
    assert stop.reason == "end"
    # One stop before each (IMG): 18 readings in the script, each read once.
    assert len(stops) == [entry.call for entry in session.trace].count("IMG") == 18
    for stop, made in stops:
        assert (session.trace[made].call, session.trace[made].line) == ("IMG", stop.line)
    assert [stop.line for stop, _ in stops[:5]] == [4, 4, 4, 6, 7]
    assert {stop.text for stop, _ in stops} == {"(IMG)"}


def test_a_call_breakpoint_on_a_form_stops_only_there() -> None:
    session = _session(LISTING_1)
    session.set_call_breakpoints(["cam p"])
    lines = []
    while (stop := session.continue_()).reason == "call":
        assert stop.text == "(CAM P)"
        lines.append(stop.line)
    # (CAM P c) once, then (CAM P C) in each of the five passes of the :14 loop; the
    # :22 loop's (CAM P C) never runs: the approach keeps x within 60..200.
    assert lines == [12, 18, 18, 18, 18, 18]


LOSING = "(TRC 3); (MOV 1,1)\n(TIM 10)\n(END)\n:96 H=1\n(MOV 0,0)\n"


def test_a_lost_line_stops_at_its_handler_when_asked() -> None:
    script = parse_script({"line_lost": [{"time": 500}]})
    session = _session(LOSING, lambda: ScriptedDevice(script))
    session.stop_on_lost_line = True
    stop = session.continue_()
    assert stop == Stop("lost-line", 4, "line lost (mode 3, MOV): jump to :96")
    assert session.trace[-1].call == LOST
    assert session.device_state()["time (ms)"] == 500
    assert session.continue_() == Stop("end", None, "the program ended")
    assert session.variables["H"] == 1


def test_a_lost_line_does_not_stop_a_continue_unless_asked() -> None:
    script = parse_script({"line_lost": [{"time": 500}]})
    session = _session(LOSING, lambda: ScriptedDevice(script))
    assert session.continue_().reason == "end"
    assert session.variables["H"] == 1


def test_a_fault_stops_on_its_line_and_ends_the_run() -> None:
    session = _session("A=5\nA=A-10\n(TIM A)\nB=1\n")
    session.set_line_breakpoints([(4, None)])
    stop = session.continue_()
    assert stop.reason == "fault" and stop.line == 3
    assert stop.text.startswith("E1010: argument tenths of (TIM) is -5 (the value of A)")
    assert session.over and session.result is not None and session.result.fault is not None
    assert session.result.fault.kind is FaultKind.ARGUMENT_RANGE
    assert session.continue_() == stop  # the run is over: it stays so
    assert session.step_line() == stop
    assert [entry.call for entry in session.trace] == ["STOP"]


def test_stepping_a_line_runs_its_statements_and_names_what_changed() -> None:
    session = _session("A=1; B=2\nC=A+B\nA++\n")
    assert session.line == 1
    assert session.step_line() == Stop("step", 2)
    assert session.changed == {"A", "B"}
    assert session.step_line() == Stop("step", 3)
    assert (session.changed, session.variables["C"]) == ({"C"}, 3)
    assert session.step_instruction() == Stop("step", 3)  # the (END) after A++ is line 3's
    assert session.changed == {"A"}
    assert session.step_instruction() == Stop("end", None, "the program ended")


def test_a_jump_back_to_the_same_line_enters_it_again() -> None:
    # One line is the whole loop: a step stops at it each time round.
    session = _session("A=-5\n:10 A++; ?A<#10\nB=1\n", budget=1000)
    session.set_line_breakpoints([(2, "A+3=0")])
    assert session.continue_() == Stop("breakpoint", 2, "A+3=0")
    assert session.variables["A"] == -3
    assert session.step_line() == Stop("step", 2)
    assert session.variables["A"] == -2


def test_pause_stops_a_continue_from_another_thread() -> None:
    session = _session(":10 A++; #10\n", budget=10**9)
    stops: list[Stop] = []
    running = threading.Thread(target=lambda: stops.append(session.continue_()))
    running.start()
    while session.machine.executed < 1000:
        threading.Event().wait(0.001)
    session.pause()
    running.join(timeout=60)
    assert not running.is_alive()
    (stop,) = stops
    assert stop == Stop("pause", 1, "paused")
    assert not session.over


class _PausingDevice(ScriptedDevice):
    """Asks the session to pause when the program lights the lamp, as a user would."""

    session: Session

    def lamp(self, on: int) -> None:
        super().lamp(on)
        self.session.pause()


def test_pause_stops_right_after_the_instruction_under_way() -> None:
    device = _PausingDevice()
    session = _session("A=1\n(LMP 1)\nB=2\nC=3\n", lambda: device)
    device.session = session
    assert session.continue_() == Stop("pause", 3, "paused")
    assert session.variables["B"] == 0


def test_restart_runs_again_from_the_start_on_a_new_device() -> None:
    session = _session(LISTING_1)
    session.set_line_breakpoints([(20, None)])
    first = session.continue_()
    while not session.over:
        session.continue_()
    ended = session.result
    assert session.restart() == Stop("entry", 2)
    assert session.variables == {name: 0 for name in session.variables}
    assert session.trace == [] and not session.over
    assert session.continue_() == first
    while not session.over:
        session.continue_()
    assert session.result == ended


def test_the_simulators_state_at_line_20_of_listing_1() -> None:
    path = SAMPLE.parent / "sample.world.toml"
    world = decode_world(path.read_bytes(), str(path))
    session = _session(LISTING_1, lambda: SimDevice(world))
    session.set_line_breakpoints([(20, None)])
    assert session.continue_() == Stop("breakpoint", 20)
    state = session.device_state()
    last = session.trace[-1]
    assert isinstance(last, SimEntry)
    assert last.call == "CAM P" and last.args == (session.variables["C"],)
    assert state["camera pan (pulses)"] == session.variables["C"]  # line 18's (CAM P C)
    assert (state["x (cm)"], state["y (cm)"]) == (round(last.pose.x, 2), round(last.pose.y, 2))
    assert state["camera tilt"] == "up"  # line 12's (CAM U)
    assert state["scene"] == 2  # line 12's (SCN 2)
    assert state["tracing mode"] == 0  # line 5's (TRC 0)
    assert state["wheel speeds (units)"] == [0.0, 0.0]  # line 5's (MOV 0,0)
    assert state["steering (degrees)"] == 0.0
    img = [entry.result for entry in session.trace if entry.call == "IMG"][-1]
    assert state["last readings"] == {"IMG": list(img or ())}
    session.step_line()  # (STX D); (MOV 1,1)
    state = session.device_state()
    assert state["steering (degrees)"] == round(session.variables["D"] / 10, 2)
    assert state["wheel speeds (units)"] == [1.0, 1.0]  # tracing is off: as commanded
    assert state["motion"] == "MOV"


def test_the_session_ends_as_rl1c_run_ends_listing_1() -> None:
    session = _session(LISTING_1)
    session.set_line_breakpoints([(20, None), (35, None)])
    reasons = []
    while not session.over:
        reasons.append(session.continue_().reason)
    device = ScriptedDevice(SCRIPT)
    finished = run(LISTING_1, device)
    assert isinstance(finished, Finished)
    assert reasons == ["breakpoint", "breakpoint", "end"]
    assert session.result == finished.result and session.trace == device.trace


def test_readings_are_named_with_their_port() -> None:
    script = parse_script({"INP": {"3": [7]}, "IMG": [{"area": 1, "x": 2, "y": 3, "z": 4}]})
    session = _session("A=(INP 3)\n(IMG)\n", lambda: ScriptedDevice(script))
    session.continue_()
    assert session.device_state()["last readings"] == {"INP 3": [7], "IMG": [1, 2, 3, 4]}
