"""The VM's step interface and hardware split (spec/ilc.md, section 12): a step runs at
most its limit of instructions; stepping with any limits gives the run `run` gives; a
built-in that takes device time is started and polled; every callback's failure and a
reading out of its documented range is a device fault that stops the vehicle first."""

from __future__ import annotations

from dataclasses import dataclass, field

from hypothesis import given, settings
from hypothesis import strategies as st
from support.scripts import MOVING_STARTS, scripts
from test_machine import To, assemble, call, commands, op, v

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.strategies import checked_programs
from rl1.vm.device import NOTHING, FormKey, LineLost, Outcome
from rl1.vm.faults import FaultKind
from rl1.vm.hardware import Answer, Blocking, Status
from rl1.vm.machine import Machine, State
from rl1.vm.scripted import Script, ScriptedDevice
from rl1.vm.verifier import VerifiedProgram, verify


def _compiled(text: str) -> VerifiedProgram:
    compiled = compile_text(text, "stepped.rob")
    assert compiled.output is not None, compiled.diagnostics
    return verify(compiled.output)


@settings(max_examples=150, deadline=None)
@given(st.sampled_from(MOVING_STARTS), checked_programs(), scripts(),
       st.lists(st.integers(1, 40), min_size=1, max_size=8), st.integers(1, 3000))
def test_stepping_with_any_limits_gives_the_run_to_the_end(
    start: str, text: str, script: Script, limits: list[int], budget: int,
) -> None:
    program = _compiled(start + text)
    whole_device, stepped_device = ScriptedDevice(script), ScriptedDevice(script)
    whole = Machine(program, Blocking(whole_device), budget)
    expected = whole.run()
    stepped = Machine(program, Blocking(stepped_device), budget)
    state, steps = State.RUNNING, 0
    while state in (State.RUNNING, State.WAITING):
        before = stepped.executed
        limit = limits[steps % len(limits)]
        state = stepped.step(limit)
        steps += 1
        assert stepped.executed - before <= limit
        if state is State.RUNNING:  # a step that neither waits nor ends runs its limit
            assert stepped.executed - before == limit
    assert stepped.result == expected
    assert stepped_device.trace == whole_device.trace
    assert stepped.executed == whole.executed


def test_a_step_stops_inside_a_statement_and_resumes_there() -> None:
    """A=1+2+3 is four instructions; a limit inside them stops after exactly that many,
    with the accumulator kept for the next step."""
    machine = Machine(assemble(op("LDI", 1), op("ADDI", 2), op("ADDI", 3), op("STV", v("A")),
                               op("LDV", v("A")), op("STV", v("B"))), Blocking(ScriptedDevice()))
    assert machine.step(2) is State.RUNNING and machine.executed == 2
    assert machine.variables[v("A")] == 0 and machine.acc == 3  # the store has not run yet
    assert machine.step(2) is State.RUNNING and machine.variables[v("A")] == 6
    assert machine.step(100) is State.ENDED
    assert machine.result is not None and machine.result.named()["B"] == 6


def test_a_step_of_zero_runs_nothing_and_an_ended_run_stays_ended() -> None:
    machine = Machine(_compiled("A=1\n"), Blocking(ScriptedDevice()))
    assert machine.step(0) is State.RUNNING and machine.executed == 0
    assert machine.step(10) is State.ENDED
    executed = machine.executed
    assert machine.step(10) is State.ENDED and machine.executed == executed


@dataclass
class Fake:
    """Hardware that logs every callback: each poll answers BUSY `busy` times after a
    start, then done with the next of `readings`; the callbacks named in `failing`
    answer ERROR; during the callback `post_at` the device posts `event`."""

    busy: int = 0
    readings: list[Outcome] = field(default_factory=list)
    post_at: str = ""  # the callback during which the device posts `event`
    failing: set[str] = field(default_factory=set)  # callbacks that answer ERROR
    log: list[str] = field(default_factory=list)
    event: LineLost | None = None
    _left: int = 0

    def _answer(self, name: str, outcome: Outcome = NOTHING) -> Answer:
        self.log.append(name)
        if name == self.post_at:
            self.pending_event = self.event
        if name in self.failing:
            return Answer(Status.ERROR, message=f"{name} failed")
        return Answer(Status.OK, outcome)

    def begin(self) -> Answer:
        return self._answer("begin")

    def call(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        return self._answer(f"call {form[0]}",
                            self.readings.pop(0) if self.readings else NOTHING)

    def start(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        self._left = self.busy
        return self._answer(f"start {form[0]}")

    def poll(self) -> Answer:
        if self._left:
            self._left -= 1
            self.log.append("busy")
            return Answer(Status.BUSY)
        return self._answer("poll", self.readings.pop(0) if self.readings else NOTHING)

    def stop(self) -> Answer:
        return self._answer("stop")

    def end(self) -> Answer:
        return self._answer("end")

    pending_event: LineLost | None = None  # in the mailbox

    @property
    def pending(self) -> LineLost | None:
        return self.pending_event

    def take_event(self) -> LineLost | None:
        event, self.pending_event = self.pending_event, None
        return event


def test_a_busy_poll_waits_without_running_instructions() -> None:
    fake = Fake(busy=2, readings=[Outcome(150)])
    machine = Machine(assemble(op("INC", v("A")), call("ULTA"), op("LDR"), op("STV", v("B"))),
                      fake)
    assert machine.step(10) is State.WAITING and machine.executed == 2
    assert machine.step(10) is State.WAITING and machine.executed == 2
    assert machine.step(10) is State.ENDED
    assert machine.result is not None and machine.result.named()["B"] == 150
    assert fake.log == ["begin", "start ULT", "busy", "busy", "poll", "end"]


def test_calls_that_take_no_device_time_are_one_callback() -> None:
    fake = Fake()
    machine = Machine(assemble(call("MOV", 1, 1), call("TRC", 2), call("TIM", 1)), fake)
    assert machine.run().fault is None
    assert fake.log == ["begin", "call MOV", "call TRC", "start TIM", "poll", "end"]


def _fault_of(fake: Fake, *ops: tuple[str, tuple[int | To, ...], tuple[object, ...]]
              ) -> tuple[FaultKind, str, int | None]:
    result = Machine(assemble(*ops), fake).run()  # type: ignore[arg-type]
    assert result.fault is not None
    return result.fault.kind, result.fault.message, result.fault.line


def test_each_failing_callback_is_a_device_fault_that_stops_first() -> None:
    for failing, at in (("start TIM", 2), ("poll", 2), ("call MOV", 1)):
        fake = Fake(failing={failing})
        kind, message, line = _fault_of(fake, call("MOV", 1, 1), call("TIM", 3))
        assert (kind, message, line) == (FaultKind.DEVICE, f"{failing} failed", at)
        assert fake.log[-2:] == ["stop", "end"]


def test_a_failing_begin_faults_before_the_first_instruction() -> None:
    fake = Fake(failing={"begin"})
    machine = Machine(assemble(op("INC", v("A"))), fake)
    assert machine.step(5) is State.FAULTED and machine.executed == 0
    assert machine.result is not None and machine.result.fault is not None
    assert (machine.result.fault.kind, machine.result.fault.line) == (FaultKind.DEVICE, None)


def test_a_failing_stop_keeps_the_fault_and_says_so() -> None:
    fake = Fake(failing={"poll", "stop"})
    kind, message, _ = _fault_of(fake, call("TIM", 3))
    assert (kind, message) == (FaultKind.DEVICE,
                               "poll failed; stopping the vehicle failed too: stop failed")


def test_readings_out_of_their_documented_range_are_device_faults() -> None:
    for opcode, reading, message in (
            ("INP", 256, "(INP) returned 256, outside its range 0..255"),
            ("INP", -1, "(INP) returned -1, outside its range 0..255"),
            ("CAMR", 785, "(CAM R) returned 785, outside its range 0..784")):
        fake = Fake(readings=[Outcome(reading)])
        ops = (call(opcode, 3),) if opcode == "INP" else (call(opcode),)
        assert _fault_of(fake, *ops) == (FaultKind.DEVICE, message, 1)
    for opcode, reading in (("INP", 255), ("CAMR", 784), ("CAMR", 0)):
        fake = Fake(readings=[Outcome(reading)])
        machine = Machine(assemble(call(opcode, 3) if opcode == "INP" else call(opcode),
                                   op("LDR"), op("STV", v("A"))), fake)
        result = machine.run()
        assert result.fault is None and result.named()["A"] == reading


def test_an_event_pending_at_the_end_is_dropped_and_end_does_not_stop() -> None:
    device = ScriptedDevice()
    machine = Machine(assemble(op("INC", v("A")), op("END"), op("INC", v("B")),
                               handlers={98: 2}), Blocking(device))
    assert machine.step(1) is State.RUNNING
    device.pending = LineLost("MOV", 2)
    assert machine.step(5) is State.ENDED
    assert machine.result is not None and machine.result.named()["B"] == 0
    assert device.pending is not None and device.trace == []


def test_a_loss_posted_before_the_program_begins_is_dropped() -> None:
    fake = Fake(event=LineLost("MOV", 3), post_at="begin")
    result = Machine(assemble(call("KYC"), op("INC", v("A")), op("END"),
                              op("INC", v("H")), handlers={96: 3}), fake).run()
    assert (result.named()["A"], result.named()["H"]) == (1, 0)


def test_an_event_is_taken_after_a_call_that_takes_no_time_and_at_a_taken_jump() -> None:
    fake = Fake(event=LineLost("MOV", 3), post_at="call KYC")
    result = Machine(assemble(call("KYC"), op("INC", v("A")), op("END"),
                              op("INC", v("H")), handlers={96: 3}), fake).run()
    assert (result.named()["A"], result.named()["H"]) == (0, 1)
    device = ScriptedDevice()
    machine = Machine(assemble(op("INC", v("A")), op("JMP", To(0)), op("INC", v("H")),
                               handlers={96: 2}), Blocking(device))
    assert machine.step(2) is State.RUNNING and machine.variables[v("A")] == 1
    device.pending = LineLost("MOV", 3)  # posted between two instructions
    assert machine.step(1) is State.RUNNING and machine.pc == 1  # INC A takes no event
    assert machine.step(1) is State.RUNNING and machine.pc == 2  # the JMP took it
    assert commands(device) == [] and machine.variables[v("A")] == 2


def test_a_failing_end_is_a_device_fault_at_the_end_and_end_is_not_called_twice() -> None:
    fake = Fake(failing={"end"})
    kind, message, line = _fault_of(fake, op("INC", v("A")), op("END"))
    assert (kind, message, line) == (FaultKind.DEVICE, "end failed", 2)
    assert fake.log == ["begin", "end", "stop"]
