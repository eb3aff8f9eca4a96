"""Rules of the reference VM that no test held until mutation testing (tests/mutation/)
changed them and every test still passed: each test here fails on such a mutant of
vm/machine.py, and says which rule of spec/ilc.md it holds."""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT
from support.semantics import int16
from test_machine import To, assemble, call, execute, int16s, op, v
from test_stepping import Fake

from rl1.vm.device import FormKey
from rl1.vm.faults import ABORTED_MESSAGE, Fault, FaultKind
from rl1.vm.hardware import Answer
from rl1.vm.language import VARIABLES
from rl1.vm.machine import Machine, State

# Each conditional jump: whether it jumps on the value its variable holds when tested.
CONDITIONAL_JUMPS: dict[str, Callable[[int], bool]] = {
    "JZ": lambda value: value == 0,
    "JGT": lambda value: value > 0,
    "JLT": lambda value: value < 0,
    "DJGT": lambda value: value > 0,  # tested once decremented
    "SJZ": lambda value: value == 0,  # tested once the accumulator is stored in it
    "SJGT": lambda value: value > 0,
    "SJLT": lambda value: value < 0,
}


# The states a step answers (section 12) ------------------------------------------------

def test_the_states_are_the_c_headers_each_apart() -> None:
    """vm/native.py reads the C VM's state as `State(number)`, so each state has the
    number of its RL1_ name in spec/rl1_hardware.h (RL1_IN_STEP, which a step never
    returns, aside), and no two states are one."""
    header = (ROOT / "spec" / "rl1_hardware.h").read_text(encoding="utf-8")
    states = header[header.index("typedef enum {\n    RL1_RUNNING"):header.index("} rl1_state;")]
    numbers = {name: int(number) for name, number in re.findall(r"RL1_(\w+) = (\d+)", states)}
    assert {state.name: state.value for state in State} == \
        {name: number for name, number in numbers.items() if name != "IN_STEP"}

# What the optimizer's budget invariant bounds (spec/optimization.md, section 3) ------

def test_each_call_counts_the_instructions_run_up_to_it_itself_included() -> None:
    machine = Machine(assemble(op("INC", v("A")), op("INC", v("B")), call("MOV", 1, 1),
                               op("INC", v("C")), call("TIM", 1), op("JMP", To(6)),
                               call("TRC", 2)), Fake(busy=1))
    assert machine.run().fault is None
    assert machine.call_counts == [3, 5, 7]

# Aborts (section 12.7): the fault is placed at the instruction at hand ---------------

def test_an_abort_before_the_first_step_faults_at_the_first_line() -> None:
    machine = Machine(assemble(op("INC", v("A")), op("INC", v("B"))), Fake())
    machine.abort()
    assert machine.step(10) is State.FAULTED
    assert machine.executed == 0
    assert machine.result is not None
    assert machine.result.fault == Fault(FaultKind.ABORTED, ABORTED_MESSAGE, 1)


def test_an_abort_while_a_call_waits_faults_at_the_call_and_stops_first() -> None:
    fake = Fake(busy=5)
    machine = Machine(assemble(op("INC", v("A")), call("TIM", 3), op("INC", v("B"))), fake)
    assert machine.step(10) is State.WAITING
    machine.abort()
    assert machine.step(10) is State.FAULTED
    assert machine.result is not None
    assert machine.result.fault == Fault(FaultKind.ABORTED, ABORTED_MESSAGE, 2)
    assert machine.result.named()["B"] == 0
    assert fake.log[-2:] == ["stop", "end"]



def test_an_abort_past_the_last_instruction_faults_at_the_last_one_run() -> None:
    machine = Machine(assemble(op("INC", v("A")), op("INC", v("B"))), Fake())
    assert machine.step(2) is State.RUNNING  # both run; the end is the next step's
    machine.abort()
    assert machine.step(10) is State.FAULTED
    assert machine.result is not None
    assert machine.result.fault == Fault(FaultKind.ABORTED, ABORTED_MESSAGE, 2)


@dataclass
class AbortingInCall(Fake):
    """Hardware whose calls that take no device time abort the machine they serve, as an
    interrupt handler may while the VM waits for the callback."""

    machine: list[Machine] = field(default_factory=list)

    def call(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        self.machine[0].abort()
        return super().call(form, args)


def test_an_abort_during_a_call_is_taken_at_its_event_point() -> None:
    hardware = AbortingInCall()
    machine = Machine(assemble(op("INC", v("A")), call("MOV", 1, 1), op("INC", v("B"))),
                      hardware)
    hardware.machine.append(machine)
    assert machine.step(10) is State.FAULTED
    assert machine.result is not None
    assert machine.result.fault == Fault(FaultKind.ABORTED, ABORTED_MESSAGE, 2)
    assert machine.result.named()["B"] == 0
    assert hardware.log == ["begin", "call MOV", "stop", "end"]


def test_an_abort_after_the_end_changes_nothing() -> None:
    fake = Fake()
    machine = Machine(assemble(op("INC", v("A"))), fake)
    ended = machine.run()
    machine.abort()
    assert machine.step(10) is State.ENDED
    assert machine.result == ended and ended.fault is None
    assert fake.log == ["begin", "end"]

# Conditional jumps test their own variable (section 8.3) ----------------------------

def jumps_on_its_variable_alone(name: str, value: int) -> None:
    """The tested variable is `a`; every other variable, among them those whose index is
    the jump's target offset, holds a value that decides the jump the other way."""
    jumps = CONDITIONAL_JUMPS[name]
    tested = int16(value - 1) if name == "DJGT" else value
    decoy = next(other for other in (-1, 0, 1) if jumps(other) != jumps(tested))
    setup = [op("MOVI", index, decoy) for index in range(len(VARIABLES)) if index != v("a")]
    setup.append(op("LDI", value) if name.startswith("S") else op("MOVI", v("a"), value))
    end = len(setup) + 2
    # No line map: MOVI is of format 1.2, whose line map needs a source digest.
    program = assemble(*setup, op(name, v("a"), To(end)), op("MOVI", v("@"), 7),
                       op("END"), debug=False)
    variables = execute(program)[0].named()
    assert variables["@"] == (decoy if jumps(tested) else 7), value
    assert variables["a"] == tested


@pytest.mark.parametrize("name", sorted(CONDITIONAL_JUMPS))
def test_a_conditional_jump_tests_its_variable_at_the_edges(name: str) -> None:
    for value in (-32768, -2, -1, 0, 1, 2, 32767):
        jumps_on_its_variable_alone(name, value)


@settings(max_examples=100, deadline=None)
@given(st.sampled_from(sorted(CONDITIONAL_JUMPS)), int16s)
def test_a_conditional_jump_tests_its_variable_whatever_the_others_hold(
        name: str, value: int) -> None:
    jumps_on_its_variable_alone(name, value)
