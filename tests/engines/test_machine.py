"""The reference VM on hand-built bytecode: every instruction kind, wrap-around, shift
counts, lost-line handler jumps, the watchdog, every fault kind; and, on generated
programs, the same traces, variables and faults as the AST interpreter."""

from __future__ import annotations

from dataclasses import dataclass

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import EXAMPLES
from support.ilc import images
from support.scripts import MOVING_STARTS, scripts
from support.semantics import int16, operate

from rl1.compiler.runner import Finished, load_script
from rl1.compiler.runner import run as run_program
from rl1.compiler.strategies import checked_programs
from rl1.vm import ilc, isa
from rl1.vm.device import DeviceError, FuzzyReading, ImageReading, LineLost, Odometry
from rl1.vm.faults import FaultKind, RunResult
from rl1.vm.hardware import Blocking
from rl1.vm.language import BUILTINS, VARIABLES
from rl1.vm.machine import Machine
from rl1.vm.scripted import LossAt, LossDuring, Script, ScriptedDevice, TraceEntry
from rl1.vm.verifier import VerifiedProgram, verify


@dataclass(frozen=True)
class To:
    """A jump target: the instruction at this index."""

    index: int


Op = tuple[str, tuple[int | To, ...], tuple[isa.Arg, ...]]


def op(name: str, *operands: int | To) -> Op:
    return (name, operands, ())


def call(name: str, *args: int | str) -> Op:
    """A call; a str argument is a variable's name, an int a constant."""
    return (name, (), tuple(isa.Arg(True, VARIABLES.index(arg)) if isinstance(arg, str)
                            else isa.Arg(False, arg) for arg in args))


def v(name: str) -> int:
    return VARIABLES.index(name)


def assemble(*ops: Op, handlers: dict[int, int] | None = None, debug: bool = True
             ) -> VerifiedProgram:
    """Instruction i is on source line i + 1 of the line map; `handlers` maps a label to
    an instruction index."""
    infos = [isa.BY_NAME[name] for name, _, _ in ops]
    offsets = [sum(info.length for info in infos[:i]) for i in range(len(infos))]
    code = b"".join(
        isa.encode(info, tuple(offsets[o.index] if isinstance(o, To) else o
                               for o in operands), args)
        for info, (_, operands, args) in zip(infos, ops, strict=True))
    builtins = [BUILTINS[info.builtin[0]] for info in infos if info.builtin is not None]
    features = frozenset(b.feature for b in builtins if b.feature is not None)
    lines = ilc.DebugInfo("t.rob", tuple((offset, i + 1) for i, offset in enumerate(offsets)))
    image = ilc.Image(code, {label: offsets[i] for label, i in (handlers or {}).items()},
                      features, lines if debug else None)
    return verify(ilc.encode(image))


def execute(program: VerifiedProgram, script: Script | None = None, budget: int = 10_000
            ) -> tuple[RunResult, ScriptedDevice]:
    device = ScriptedDevice(script)
    return Machine(program, Blocking(device), budget).run(), device


def commands(device: ScriptedDevice) -> list[str]:
    return [" ".join([entry.call, *map(str, entry.args)]) for entry in device.trace]


# Instructions ---------------------------------------------------------------------------

int16s = st.integers(-32768, 32767)
OPERATORS = dict(zip(isa.ALU_OPERATORS, ("ADD", "SUB", "AND", "OR", "XOR", "SHL", "SHR"),
                     strict=True))


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(isa.ALU_OPERATORS), st.sampled_from("VIR"), int16s, int16s,
       st.booleans())
def test_each_alu_instruction_with_each_operand_kind(
    operator: str, kind: str, left: int, right: int, grouped: bool,
) -> None:
    """`grouped`: the load-operate-store run executes as one expression step; otherwise
    a jump lands on the operator, which then runs as a single instruction."""
    name = OPERATORS[operator] + kind
    setup = {"V": [op("LDI", right), op("STV", v("B"))], "I": [], "R": [call("ULTA")]}[kind]
    operand = {"V": (v("B"),), "I": (right,), "R": ()}[kind]
    entry = len(setup) + 3
    start = [op("LDI", left)] if grouped else [op("LDI", left), op("JMP", To(entry)),
                                              op("LDI", 0)]
    program = assemble(*setup, *start, op(name, *operand), op("STV", v("A")), op("END"))
    result, _ = execute(program, Script(ultrasonic={"A": (right,)}))
    assert result.named()["A"] == operate(operator, left, right)


@settings(max_examples=200, deadline=None)
@given(int16s, st.lists(st.tuples(st.sampled_from(isa.ALU_OPERATORS), int16s), max_size=8))
def test_a_load_operate_store_run_is_one_expression(
    first: int, steps: list[tuple[str, int]],
) -> None:
    program = assemble(op("LDI", first), *(op(OPERATORS[o] + "I", value) for o, value in steps),
                       op("STV", v("A")))
    expected = first
    for operator, value in steps:
        expected = operate(operator, expected, value)
    assert execute(program)[0].named()["A"] == expected


def test_a_jump_into_the_middle_of_an_expression_runs_its_single_instructions() -> None:
    program = assemble(op("LDI", 30000), op("JMP", To(3)),
                       op("LDI", 999), op("ADDI", 5000), op("STV", v("A")))
    assert execute(program)[0].named()["A"] == int16(35000)


def test_the_accumulator_wraps_across_jumps_and_long_shift_loops_stay_small() -> None:
    summed = assemble(op("LDI", 1000), op("STV", v("N")), op("LDI", 0),
                      op("ADDI", 30000), op("DEC", v("N")), op("JGT", v("N"), To(3)),
                      op("STV", v("A")))
    assert execute(summed)[0].named()["A"] == int16(30000 * 1000)
    shifting = assemble(op("LDI", 1), op("SHLI", 15), op("JMP", To(1)))
    result, _ = execute(shifting, budget=200_000)
    assert result.fault is not None and result.fault.kind is FaultKind.BUDGET


def test_inc_dec_wrap_and_ldr_reads_the_last_result() -> None:
    program = assemble(op("LDI", 32767), op("STV", v("A")), op("INC", v("A")),
                       op("DEC", v("B")), op("DEC", v("B")), op("LDI", -32768),
                       op("STV", v("C")), op("DEC", v("C")), call("CAMR"), op("LDR"),
                       op("STV", v("D")))
    named = execute(program, Script(camera=(392,)))[0].named()
    assert (named["A"], named["B"], named["C"], named["D"]) == (-32768, -2, 32767, 392)


@pytest.mark.parametrize(("value", "taken"), [
    (-1, {"JZ": False, "JGT": False, "JLT": True}),
    (0, {"JZ": True, "JGT": False, "JLT": False}),
    (1, {"JZ": False, "JGT": True, "JLT": False}),
    (-32768, {"JZ": False, "JGT": False, "JLT": True}),
])
def test_conditional_jumps_compare_with_zero(value: int, taken: dict[str, bool]) -> None:
    for name, jumps in taken.items():
        program = assemble(op("LDI", value), op("STV", v("X")), op(name, v("X"), To(5)),
                           op("LDI", 1), op("STV", v("A")), op("END"))
        assert execute(program)[0].named()["A"] == (0 if jumps else 1), name


def test_calls_write_reserved_variables_and_r() -> None:
    script = Script(images=(ImageReading(180, 130, 90, -4),), odometry=(Odometry(50, 52, 48),),
                    fuzzy=(FuzzyReading(7, -7),))
    program = assemble(call("IMG"), call("KYO"), op("LDR"), op("STV", v("B")), call("FZI"),
                       op("LDR"), op("STV", v("C")))
    named = execute(program, script)[0].named()
    assert {name: named[name] for name in "wxyzuvstBC"} == {
        "w": 180, "x": 130, "y": 90, "z": -4, "u": 52, "v": 48, "s": 7, "t": -7,
        "B": 50, "C": 50}  # FZI has no result: R still holds KYO's


def test_variable_arguments_reach_the_device_and_running_off_the_end_ends() -> None:
    program = assemble(op("LDI", -12), op("STV", v("L")), call("MOV", "L", 12),
                       call("CAMP", 784))
    result, device = execute(program)
    assert result.fault is None
    assert commands(device) == ["MOV -12 12", "CAM P 784"]


# Lost lines -------------------------------------------------------------------------------

HANDLER_AT = {96: 6, 97: 9, 98: 12, 99: 15}  # the instruction index of each handler


def traced(mode: int, motion: Op, labels: tuple[int, ...] = (96, 97, 98, 99)
           ) -> tuple[RunResult, ScriptedDevice]:
    """TRC mode; motion; TIM 5; A=1; END; then a handler per label that sets H to the
    label; the line is lost at 250 ms. Only `labels` are in the handler table."""
    handler_code = [code for label in HANDLER_AT
                    for code in (op("LDI", label), op("STV", v("H")), op("END"))]
    program = assemble(call("TRC", mode), motion, call("TIM", 5), op("LDI", 1),
                       op("STV", v("A")), op("END"), *handler_code,
                       handlers={label: HANDLER_AT[label] for label in labels})
    return execute(program, Script(losses=(LossAt(250),)))


@pytest.mark.parametrize(("mode", "command", "handler"), [
    (2, "MOV", 98), (2, "MVI", 99), (3, "MOV", 96), (3, "MVI", 97)])
def test_modes_2_and_3_jump_to_the_handler_of_the_command(
    mode: int, command: str, handler: int,
) -> None:
    motion = call("MOV", 2, 2) if command == "MOV" else call("MVI", 2, 2, 10)
    result, device = traced(mode, motion, (handler,))
    assert (result.named()["H"], result.named()["A"]) == (handler, 0)
    assert commands(device)[-1] == f"LINE LOST {mode}"
    assert ("TIM 5" in commands(device)) == (command == "MOV")


@pytest.mark.parametrize("mode", [0, 1])
def test_modes_0_and_1_do_not_jump(mode: int) -> None:
    for motion in (call("MOV", 2, 2), call("MVI", 2, 2, 10)):
        result, _ = traced(mode, motion, ())
        assert result.fault is None and result.named()["A"] == 1


def test_an_event_after_a_jump_is_taken_there() -> None:
    """A device that loses the line between calls: the VM takes it at the next jump."""

    class Asynchronous(ScriptedDevice):
        takes = 0  # the line is lost after the second look at the mailbox (the MOV's)

        def poll_event(self) -> LineLost | None:
            self.takes += 1
            return LineLost("MOV", 3) if self.takes == 3 else None

    program = assemble(call("MOV", 1, 1), op("INC", v("C")), op("JMP", To(1)),
                       op("LDI", 96), op("STV", v("H")), handlers={96: 3})
    device = Asynchronous()
    result = Machine(program, Blocking(device)).run()
    assert (result.named()["C"], result.named()["H"]) == (1, 96)
    assert device.takes == 3  # at the start, after the MOV, at the jump; not at END


# Faults ---------------------------------------------------------------------------------


def test_argument_out_of_range_stops_the_vehicle_first() -> None:
    program = assemble(call("MOV", 3, 3), op("LDI", 13), op("STV", v("S")),
                       call("MOV", "S", 0), op("INC", v("A")))
    result, device = execute(program)
    assert result.fault is not None
    assert (result.fault.kind, result.fault.line) == (FaultKind.ARGUMENT_RANGE, 4)
    assert result.fault.message == "argument l of (MOV) is 13 (the value of S), outside -12..12"
    assert commands(device) == ["MOV 3 3", "STOP"]
    assert result.named()["A"] == 0


def test_a_missing_handler_is_a_fault() -> None:
    result, device = traced(2, call("MOV", 2, 2), (96, 97, 99))
    assert result.fault is not None
    assert (result.fault.kind, result.fault.line) == (FaultKind.MISSING_HANDLER, 3)
    assert "jumps to :98" in result.fault.message
    assert commands(device)[-2:] == ["LINE LOST 2", "STOP"]


def test_the_watchdog_looks_at_taken_jumps_and_before_calls() -> None:
    loop = Machine(assemble(op("INC", v("A")), op("JMP", To(0))), Blocking(ScriptedDevice()), 5)
    result = loop.run()
    assert result.fault is not None
    assert (result.fault.kind, result.fault.line) == (FaultKind.BUDGET, 2)
    assert (loop.executed, result.named()["A"]) == (6, 3)
    result, device = execute(assemble(op("LDI", 0), op("LDI", 0), call("FRE")), budget=2)
    assert result.fault is not None and result.fault.kind is FaultKind.BUDGET
    assert commands(device) == ["STOP"]  # the FRE never ran
    straight = assemble(op("LDI", 1), op("STV", v("A")), op("INC", v("A")), op("END"))
    assert execute(straight, budget=1)[0].fault is None


def test_a_device_error_is_a_fault_and_a_line_needs_the_debug_section() -> None:
    for debug, line in ((True, 2), (False, None)):
        program = assemble(call("MOV", 1, 1), call("MVI", 3, -3, 10), debug=debug)
        result, device = execute(program)
        assert result.fault is not None
        assert (result.fault.kind, result.fault.line) == (FaultKind.DEVICE, line)
        assert commands(device) == ["MOV 1 1", "MVI 3 -3 10", "STOP"]


def test_a_failing_poll_or_stop_is_reported() -> None:
    class Broken(ScriptedDevice):
        def poll_event(self) -> LineLost | None:
            raise DeviceError("the serial link dropped")

        def stop(self) -> None:
            raise DeviceError("no answer")

    result = Machine(assemble(call("FRE")), Blocking(Broken())).run()
    assert result.fault is not None and result.fault.kind is FaultKind.DEVICE
    assert result.fault.message == ("the serial link dropped; stopping the vehicle failed "
                                    "too: no answer")


@settings(max_examples=200, deadline=None)
@given(images(), st.lists(st.builds(LossAt, st.integers(1, 3000)), max_size=3),
       st.integers(0, 3))
def test_any_verified_image_runs_to_an_end_or_a_fault(
    image: ilc.Image, losses: list[LossAt], mode: int,
) -> None:
    device = ScriptedDevice(Script(ultrasonic={"A": (5,)}, losses=tuple(losses)))
    device.set_tracing(mode)
    result = Machine(verify(ilc.encode(image)), Blocking(device), 500).run()
    assert len(result.variables) == len(VARIABLES)
    assert all(-32768 <= value <= 32767 for value in result.variables)


# The VM and the interpreter agree ------------------------------------------------------------

def both(text: str, script: Script) -> tuple[tuple[RunResult, ScriptedDevice],
                                             tuple[RunResult, ScriptedDevice]]:
    interpreted_device, vm_device = ScriptedDevice(script), ScriptedDevice(script)
    interpreted = run_program(text, interpreted_device, engine="ast")
    ran = run_program(text, vm_device)
    assert isinstance(interpreted, Finished) and isinstance(ran, Finished), ran
    return (interpreted.result, interpreted_device), (ran.result, vm_device)


def logged(device: ScriptedDevice) -> list[tuple[TraceEntry, int | None]]:
    """Every entry of the device's log with its source line."""
    return [(entry, entry.line) for entry in device.log]


@settings(max_examples=150, deadline=None)
@given(st.sampled_from(MOVING_STARTS), checked_programs(), scripts())
def test_vm_and_interpreter_give_the_same_trace_variables_and_fault(
    start: str, text: str, script: Script,
) -> None:
    (interpreted, interpreted_device), (ran, vm_device) = both(start + text, script)
    assert vm_device.trace == interpreted_device.trace
    assert logged(vm_device) == logged(interpreted_device)  # each entry's line included
    assert ran.variables == interpreted.variables
    assert ran.fault == interpreted.fault


def test_the_sample_takes_its_main_path_on_both_engines() -> None:
    text = (EXAMPLES / "sample.rob").read_text(encoding="utf-8")
    (interpreted, interpreted_device), (ran, vm_device) = both(
        text, load_script(EXAMPLES / "sample.sensors.json"))
    assert ran == interpreted and vm_device.trace == interpreted_device.trace
    assert ran.fault is None
    trace = commands(vm_device)
    # Tracing stops at the branch mark, the camera settles on the stand, the approach
    # stops past y 160, the vehicle steers back to the line and finishes.
    assert trace[trace.index("IMG") + 3:][:2] == ["MOV 0 0", "TRC 0"]
    assert "CAM P 589" in trace and "STX 450" in trace
    assert trace[-7:] == ["MOV 0 0", "STR 75", "TRC 3", "MVI 1 1 50", "MOV 3 3",
                          "MOV 0 0", "FRE"]
    assert ran.named()["Y"] == 5  # the approach ended at y = 165


def test_the_sample_faults_without_a_97_handler_when_the_line_is_lost_in_its_mvi() -> None:
    text = (EXAMPLES / "sample.rob").read_text(encoding="utf-8")
    sensors = load_script(EXAMPLES / "sample.sensors.json")
    script = Script(images=sensors.images, losses=(LossDuring("MVI", 1, 2000),))
    (interpreted, _), (ran, vm_device) = both(text, script)
    assert ran.fault == interpreted.fault
    assert ran.fault is not None
    assert (ran.fault.kind, ran.fault.line) == (FaultKind.MISSING_HANDLER, 40)
    assert commands(vm_device)[-2:] == ["LINE LOST 3", "STOP"]


def test_a_fault_where_an_event_is_taken_counts_each_instruction_once() -> None:
    # Mode 2 loses the line during the wait and there is no :98: a fault right after TIM,
    # the third instruction (the fourth with a jump taken before it).
    loss = Script(losses=(LossAt(50),))
    after_call = assemble(call("TRC", 2), call("MOV", 3, 3), call("TIM", 1), op("END"))
    result, _ = execute(after_call, loss)
    assert result.fault is not None and result.fault.kind is FaultKind.MISSING_HANDLER
    machine = Machine(after_call, Blocking(ScriptedDevice(loss)), 100)
    machine.run()
    assert machine.executed == 3
    after_jump = assemble(call("TRC", 2), call("MOV", 3, 3), op("JMP", To(3)),
                          call("TIM", 1), op("END"))
    machine = Machine(after_jump, Blocking(ScriptedDevice(loss)), 100)
    assert machine.run().fault is not None
    assert machine.executed == 4
