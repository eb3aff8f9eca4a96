"""The emergency stop (rl1_abort in C, Machine.abort in the reference VM): on generated
programs, an abort between steps or from inside a callback (where an interrupt handler
would call it) gives both VMs the same fault ABORTED, at the same line, after the same
instructions and device trace. vm/c/test/run_control.c tests the C side alone (a signal
handler, callbacks that step the VM again, a patrol's budget): `make -C vm/c
run-control`."""

from __future__ import annotations

import ctypes
from dataclasses import dataclass, field

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.c_vm import sanitized_library
from support.hardware import Relay
from support.scripts import MOVING_STARTS, scripts

from rl1.compiler.backend.driver import OPTIMIZATION_LEVELS, compile_text
from rl1.compiler.strategies import checked_programs
from rl1.vm import native
from rl1.vm.device import FormKey
from rl1.vm.faults import ABORTED_MESSAGE, Fault, FaultKind, RunResult
from rl1.vm.hardware import Answer, Blocking
from rl1.vm.machine import Machine, State
from rl1.vm.scripted import Script, ScriptedDevice
from rl1.vm.verifier import verify

GOING = (State.RUNNING, State.WAITING)


@pytest.fixture(scope="session")
def c_vm(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    return native.load(sanitized_library(tmp_path_factory))


def _compiled(text: str, level: int = 0) -> bytes:
    compiled = compile_text(text, "generated.rob", level=level)
    assert compiled.output is not None, compiled.diagnostics
    return compiled.output


@dataclass
class Aborting(Relay):
    """Blocking hardware that calls `abort` from inside its callback number `at` (1 the
    first), as an interrupt handler would while the VM runs; never when `at` is 0."""

    at: int
    abort: list[Machine | native.NativeMachine] = field(default_factory=list)
    calls: int = 0

    def _count(self, answer: Answer) -> Answer:
        self.calls += 1
        if self.calls == self.at:
            self.abort[0].abort()
        return answer

    def begin(self) -> Answer:
        return self._count(self.inner.begin())

    def call(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        return self._count(self.inner.call(form, args))

    def start(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        return self._count(self.inner.start(form, args))

    def poll(self) -> Answer:
        return self._count(self.inner.poll())


def _run(machine: Machine | native.NativeMachine, device: ScriptedDevice,
         slices: list[int], abort_before: int) -> tuple[RunResult, list[object], int, bool]:
    """Steps `machine` by `slices`, aborting before step number `abort_before` (none
    when it is past the last), then to its end; the last field says whether that abort
    came while the run was going."""
    aborted = False
    for index, limit in enumerate(slices):
        if index == abort_before:
            aborted = machine.state in GOING
            machine.abort()
        if machine.step(limit) not in GOING:
            break
    return machine.run(), list(device.trace), machine.executed, aborted


@settings(max_examples=80, deadline=None)
@given(st.sampled_from(MOVING_STARTS), checked_programs(max_blocks=3), scripts(),
       st.lists(st.integers(0, 9), min_size=1, max_size=12), st.integers(0, 14),
       st.integers(0, 12), st.sampled_from(OPTIMIZATION_LEVELS))
def test_an_abort_ends_both_vms_alike(c_vm: ctypes.CDLL, start: str, text: str,
                                      script: Script, slices: list[int], abort_before: int,
                                      in_callback: int, level: int) -> None:
    data = _compiled(start + text, level)
    runs = []
    for make in (lambda hw: Machine(verify(data), hw, 5000),
                 lambda hw: native.NativeMachine(data, hw, 5000, c_vm)):
        device = ScriptedDevice(script)
        hardware = Aborting(Blocking(device), in_callback)
        machine = make(hardware)
        hardware.abort.append(machine)
        runs.append(_run(machine, device, slices, abort_before))
    expected, got = runs
    assert got == expected
    if expected[3]:  # the next step takes an abort made between steps, whatever it is
        assert expected[0].fault is not None
        assert (expected[0].fault.kind, expected[0].fault.message) == (FaultKind.ABORTED,
                                                                        ABORTED_MESSAGE)


def test_an_abort_between_steps_stops_the_vehicle_at_the_next_step(c_vm: ctypes.CDLL) -> None:
    data = _compiled("(TRC 2); (MOV 3,3)\n:10 (TIM 5); C=C+1; #10\n:98 (END)\n")
    results = []
    for make in (lambda hw: Machine(verify(data), hw, 5000),
                 lambda hw: native.NativeMachine(data, hw, 5000, c_vm)):
        device = ScriptedDevice(Script())
        machine = make(Blocking(device))
        assert machine.step(7) is State.RUNNING
        machine.abort()
        assert machine.step(7) is State.FAULTED
        assert machine.executed == 7
        assert machine.result is not None
        assert machine.result.fault == Fault(FaultKind.ABORTED, ABORTED_MESSAGE, 2)
        assert [entry.call for entry in device.trace][-1] == "STOP"
        machine.abort()  # once over, an abort changes nothing
        assert machine.step(7) is State.FAULTED
        results.append((machine.result, device.trace))
    assert results[0] == results[1]


@dataclass
class SteppingAgain(Relay):
    """Blocking hardware whose first call steps the machine that called it."""

    machine: list[native.NativeMachine] = field(default_factory=list)
    nested: list[State] = field(default_factory=list)

    def call(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        if not self.nested:
            self.nested.append(self.machine[0].step(100))
        return self.inner.call(form, args)


def test_a_callback_that_steps_the_c_vm_again_faults_the_step(c_vm: ctypes.CDLL) -> None:
    """It counted to 1 instead of 14 and ended; now the call faults, the count untouched."""
    data = _compiled("C=0\n:10 (KYC); C=C+1; D=C-14; ?D<#10\n(END)\n")
    device = ScriptedDevice(Script())
    hardware = SteppingAgain(Blocking(device))
    machine = native.NativeMachine(data, hardware, 5000, c_vm)
    hardware.machine.append(machine)
    result = machine.run()
    assert hardware.nested == [State.FAULTED]
    assert result.fault is not None
    assert (result.fault.kind, result.fault.line) == (FaultKind.DEVICE, 2)
    assert result.fault.message.startswith("a callback stepped the VM that called it")
    assert result.variables[2] == 0  # C
    assert [entry.call for entry in device.trace] == ["KYC", "STOP"]


COUNT_TOP = 2**32 - 1  # where the C VM's u32 count stops


def _steps_from(machine: Machine | native.NativeMachine, device: ScriptedDevice,
                count: int, slices: list[int]) -> list[object]:
    """Each step's state, count (at most COUNT_TOP) and variables, the count first set to
    `count` between steps as firmware tops up a patrol's budget; then the result and the
    trace. Bounded: a run past its budget that the watchdog misses would run for hours."""
    machine.executed = count
    steps: list[object] = []
    for limit in slices:
        state = machine.step(limit)
        steps.append((state, min(machine.executed, COUNT_TOP), tuple(machine.variables)))
        if state not in GOING:
            break
    return [*steps, machine.result, list(device.trace)]


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(MOVING_STARTS), checked_programs(max_blocks=3), scripts(),
       st.sampled_from((2**31 - 1, 2**31, 2**32 - 2, COUNT_TOP)), st.integers(-40, 3),
       st.lists(st.integers(0, 9), min_size=1, max_size=40), st.sampled_from(OPTIMIZATION_LEVELS))
def test_a_budget_near_2_to_the_32_faults_both_vms_alike(
        c_vm: ctypes.CDLL, start: str, text: str, script: Script, budget: int, offset: int,
        slices: list[int], level: int) -> None:
    # The count set near the budget, then stepped in slices: the same steps, fault and
    # trace on both VMs; the C VM's count stops at 2^32 - 1 where the reference VM's goes
    # on (it wrapped to 0, and the run went on past its budget).
    data = _compiled(start + text, level)
    count = min(budget + offset, COUNT_TOP)
    runs = []
    for make in (lambda hw: Machine(verify(data), hw, budget),
                 lambda hw: native.NativeMachine(data, hw, budget, c_vm)):
        device = ScriptedDevice(script)
        runs.append(_steps_from(make(Blocking(device)), device, count, slices + [50] * 20))
    assert runs[1] == runs[0]


def test_a_count_that_passes_2_to_the_32_between_steps_stops_there(c_vm: ctypes.CDLL) -> None:
    """With the budget 2^32 - 1 and steps of one instruction, the count wrapped to 0 and
    the loop ran on; now it stops at 2^32 - 1 and the loop's jump faults, as in Python."""
    data = _compiled(":10 A=A+1; B=B+1; C=C+1; D=D+1; #10\n")
    runs = []
    for make in (lambda hw: Machine(verify(data), hw, COUNT_TOP),
                 lambda hw: native.NativeMachine(data, hw, COUNT_TOP, c_vm)):
        device = ScriptedDevice(Script())
        runs.append(_steps_from(make(Blocking(device)), device, COUNT_TOP - 2, [1] * 20))
    assert runs[1] == runs[0]
    result = runs[0][-2]
    assert isinstance(result, RunResult) and result.fault is not None
    assert (result.fault.kind, result.fault.line) == (FaultKind.BUDGET, 1)
