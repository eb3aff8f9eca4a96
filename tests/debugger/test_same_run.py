"""The debugging core's promise: however a run is stepped (instructions, lines,
continues to breakpoints, stops on lost lines), it is the run `runner.run` makes, to
the bit: the same trace (and log of losses), ending, variables and instruction count,
on the scripted device with any sensor script and on the simulator."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import SAMPLE
from support.worlds import line_world

from rl1.compiler.debugger import Session, Stop, compile_program
from rl1.compiler.runner import Finished, run
from rl1.compiler.strategies import Run, runs
from rl1.vm.device import Device
from rl1.vm.scripted import ScriptedDevice
from rl1.vm.sensor_script import parse_script
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.world import World, decode_world

EXAMPLES = SAMPLE.parent
LISTING_1 = SAMPLE.read_text(encoding="utf-8")
ACTIONS = ("instruction", "line", "continue")
BUDGET = 20_000


def _sample_world() -> World:
    path = EXAMPLES / "sample.world.toml"
    return decode_world(path.read_bytes(), str(path))


def _stepped(session: Session, data: st.DataObject, lines: int) -> list[Stop]:
    """Step `session` to its end by the mix of commands `data` draws, with breakpoints
    drawn on its lines and calls."""
    session.set_line_breakpoints((line, None) for line in data.draw(
        st.sets(st.integers(1, lines), max_size=4), label="line breakpoints"))
    session.set_call_breakpoints(data.draw(st.sets(st.sampled_from(
        ("IMG", "MOV", "TIM", "KYO", "CAM", "CAM R", "ULT A", "MVI")), max_size=2),
        label="call breakpoints"))
    session.stop_on_lost_line = data.draw(st.booleans(), label="stop on lost lines")
    commands: dict[str, Callable[[], Stop]] = {
        "instruction": session.step_instruction, "line": session.step_line,
        "continue": session.continue_}
    stops: list[Stop] = []
    while not session.over:
        # A short run of single steps, then anything: the runs stay a few hundred steps.
        action = data.draw(st.sampled_from(ACTIONS), label="command") if len(
            stops) < 30 else "continue"
        stops.append(commands[action]())
    return stops


def _assert_same(session: Session, finished: Finished | object, device: Device) -> None:
    assert isinstance(finished, Finished)
    assert session.result == finished.result
    assert session.machine.executed == finished.instructions
    match session.device, device:
        case ScriptedDevice() as stepped, ScriptedDevice() as whole:
            assert stepped.trace == whole.trace
            assert [entry.line for entry in stepped.log] == [entry.line for entry in whole.log]
            assert stepped.log == whole.log
            assert stepped.time == whole.time
        case SimDevice() as stepped, SimDevice() as whole:
            assert stepped.trace == whole.trace
            assert stepped.sim.time == whole.sim.time
            assert stepped.sim.pose == whole.sim.pose
            assert stepped.sim.events == whole.sim.events
        case _:
            raise AssertionError("two devices of one kind")


@settings(max_examples=120)
@given(runs(instruction_losses=True), st.data())
def test_any_stepping_on_a_sensor_script_is_the_runners_run(case: Run, data: st.DataObject
                                                            ) -> None:
    script = parse_script(case.script)
    image = compile_program(case.source, "program.rob")
    assert isinstance(image, bytes)
    session = Session(image, lambda: ScriptedDevice(script), BUDGET)
    _stepped(session, data, case.source.count("\n") + 1)
    whole = ScriptedDevice(script)
    _assert_same(session, run(case.source, whole, budget=BUDGET), whole)


@settings(max_examples=25)
@given(runs(max_blocks=3), st.data())
def test_any_stepping_on_the_simulator_is_the_runners_run(case: Run, data: st.DataObject
                                                          ) -> None:
    world = line_world(offset=data.draw(st.integers(-3, 3), label="offset"))
    image = compile_program(case.source, "program.rob")
    assert isinstance(image, bytes)
    session = Session(image, lambda: SimDevice(world), BUDGET)
    _stepped(session, data, case.source.count("\n") + 1)
    whole = SimDevice(world)
    _assert_same(session, run(case.source, whole, budget=BUDGET), whole)


@settings(max_examples=10)
@given(st.data())
def test_listing_1_stepped_any_way_on_the_sample_world_is_rl1c_sims_run(
        data: st.DataObject) -> None:
    world = _sample_world()
    image = compile_program(LISTING_1, "sample.rob")
    assert isinstance(image, bytes)
    session = Session(image, lambda: SimDevice(world))
    _stepped(session, data, LISTING_1.count("\n"))
    whole = SimDevice(world)
    _assert_same(session, run(LISTING_1, whole), whole)


@pytest.mark.parametrize("stepping", ["instruction", "line"])
def test_listing_1_stepped_to_its_end_on_the_sample_world_is_rl1c_sims_run(
        stepping: str) -> None:
    world = _sample_world()
    image = compile_program(LISTING_1, "sample.rob")
    assert isinstance(image, bytes)
    session = Session(image, lambda: SimDevice(world))
    step = session.step_instruction if stepping == "instruction" else session.step_line
    while not session.over:
        step()
    whole = SimDevice(world)
    _assert_same(session, run(LISTING_1, whole), whole)
