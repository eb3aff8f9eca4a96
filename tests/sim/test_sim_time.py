"""Simulated time passes between calls too: each instruction the VM runs (each statement
the interpreter runs) takes `vehicle.instruction_time` (spec/simulator.md, "Time"), so
that a program polling a sensor sees the world move, as on the vehicle."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import msgspec
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.worlds import open_floor

from rl1.compiler.runner import Finished, run
from rl1.vm.defaults import Engine
from rl1.vm.faults import FaultKind, RunResult
from rl1.vm.sim.device import SimDevice
from rl1.vm.sim.simulator import DEFAULT_STEP
from rl1.vm.sim.world import Block, Vehicle, World

CORPUS = Path(__file__).parents[2] / "bench" / "corpus"
ENGINES = ["vm", pytest.param("c", marks=pytest.mark.needs_cc)]


def _world(instruction_time: float = Vehicle().instruction_time,
           blocks: tuple[Block, ...] = ()) -> World:
    world = open_floor(100.0, 500.0)
    vehicle = msgspec.structs.replace(world.vehicle, instruction_time=instruction_time)
    return replace(world, vehicle=vehicle, blocks=blocks)


def _run(world: World, text: str, engine: Engine = "vm") -> tuple[Finished, SimDevice]:
    device = SimDevice(world)
    finished = run(text, device, engine=engine)
    assert isinstance(finished, Finished)
    return finished, device


def _loop(count: int) -> str:
    """A loop of `count` rounds that makes no call, then one call, (LMP 1), and (END):
    the VM runs one instruction after the call."""
    return f"N={count}\n:10 N--; ?N>#10\n(LMP 1)\n(END)\n"


@pytest.mark.parametrize("engine", ENGINES)
@settings(max_examples=25, deadline=None)
@given(st.integers(1, 20_000), st.sampled_from([1e-5, 2e-4, 1e-3, 0.01]))
def test_the_time_of_n_instructions_is_n_times_the_instruction_time(
        engine: Engine, rounds: int, seconds: float) -> None:
    finished, device = _run(_world(seconds), _loop(rounds), engine)
    assert finished.result.fault is None and finished.instructions is not None
    (lamp,) = device.trace
    assert lamp.time == pytest.approx((finished.instructions - 1) * seconds, rel=1e-9)


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 5_000))
def test_the_interpreter_s_statements_each_take_the_instruction_time(rounds: int) -> None:
    seconds = Vehicle().instruction_time
    finished, device = _run(_world(), _loop(rounds), "ast")
    assert finished.result.fault is None
    # N=..., then N-- and ?N>#10 each round, then (LMP 1) itself.
    (lamp,) = device.trace
    assert lamp.time == pytest.approx((2 * rounds + 2) * seconds, rel=1e-9)


@pytest.mark.parametrize("engine", ENGINES)
@settings(max_examples=20, deadline=None)
@given(st.integers(1, 20_000))
def test_the_vehicle_drives_on_while_the_program_computes(engine: Engine,
                                                           rounds: int) -> None:
    finished, device = _run(_world(), "(MOV 2,2)\n" + _loop(rounds).replace("LMP 1", "FRE"),
                            engine)
    moving, stopped = device.trace
    seconds = stopped.time - moving.time
    assert finished.instructions is not None
    # The MOV is the first instruction, the FRE the one before (END).
    assert seconds == pytest.approx((finished.instructions - 2) * Vehicle().instruction_time,
                                    rel=1e-9)
    # 2 units of 5 cm/s: the arcs are exact, whatever the step.
    assert stopped.pose.x - moving.pose.x == pytest.approx(10 * seconds, abs=1e-6)


@pytest.mark.parametrize("engine", ["vm", "ast", pytest.param("c", marks=pytest.mark.needs_cc)])
def test_driving_until_the_counter_reaches_100_ends_there(engine: Engine) -> None:
    """The issue's program: it ran 10,000,000 instructions at time 0 and blamed the
    program (the budget) when polling took no time."""
    finished, device = _run(_world(), "(KYC); (MOV 3,3)\n:10 A=(KYO)-100; ?A<#10\n(FRE); (END)\n",
                            engine)
    assert finished.result.fault is None
    assert finished.result.named()["A"] == 0
    # 15 cm/s; KYO rounds to the cm, so reads 100 from 99.5 cm on, some 6.63 s after
    # the start: the loop reads it every few instructions, a few ms apart.
    assert device.sim.time == pytest.approx(99.5 / 15, abs=0.005)
    assert device.sim.pose.x == pytest.approx(199.5, abs=0.1)


def test_the_corpus_odometry_program_drives_its_3_m() -> None:
    finished, device = _run(_world(), (CORPUS / "odometry.rob").read_text())
    assert finished.result.fault is None
    assert finished.result.named()["D"] >= 300
    assert device.sim.time == pytest.approx(300 / 30, abs=0.05)  # 6 units: 30 cm/s


@pytest.mark.parametrize("engine", ENGINES)
def test_a_loop_with_no_call_drives_into_the_wall_it_never_looks_at(engine: Engine) -> None:
    wall = Block("east", ((700.0, 0.0), (710.0, 0.0), (710.0, 1000.0), (700.0, 1000.0)))
    finished, device = _run(_world(blocks=(wall,)), "(MOV 4,4)\n:10 #10\n", engine)
    fault = finished.result.fault
    assert fault is not None and fault.kind is FaultKind.DEVICE, fault
    assert "the vehicle hit the wall east" in fault.message
    assert device.fault is not None and device.fault.kind == "collision"
    # Its front, 40 cm ahead of its centre, meets x = 700 after 560 cm at 20 cm/s: found
    # within a step of the simulator (and the instructions of one stepping slice).
    assert device.fault.time == pytest.approx(560 / 20, abs=2 * DEFAULT_STEP)
    assert device.trace[-1].call == "STOP" and device.sim.motion is None
    assert finished.instructions is not None and finished.instructions < 1_000_000


def _equal_polls(result: RunResult, device: SimDevice) -> list[tuple[str, int | None]]:
    """The calls made, each run of the same call on the same line counted once."""
    calls: list[tuple[str, int | None]] = []
    for entry in device.trace:
        if not calls or calls[-1] != (entry.call, entry.line):
            calls.append((entry.call, entry.line))
    return calls


def test_the_engines_poll_the_same_calls_in_the_same_order() -> None:
    text = "(KYC); (MOV 3,3)\n:10 A=(KYO)-100; ?A<#10\n(FRE); (ROT 90); (END)\n"
    ran = {engine: _run(_world(), text, engine) for engine in ("vm", "ast")}
    (vm, on_vm), (ast, on_ast) = ran["vm"], ran["ast"]
    assert _equal_polls(vm.result, on_vm) == _equal_polls(ast.result, on_ast)
    assert vm.result == ast.result
