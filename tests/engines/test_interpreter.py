"""The AST interpreter against the language semantics: 16-bit wrapping, left-to-right
expressions, shift counts, jumps, calls and reserved variables, lost-line handlers per
tracing mode, and every kind of fault."""

from hypothesis import given, settings
from hypothesis import strategies as st
from support.semantics import operate

from rl1.compiler.analysis import analyze
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.interpreter import NotRunnable, interpret
from rl1.vm.device import ImageReading, Odometry
from rl1.vm.faults import FaultKind, RunResult
from rl1.vm.scripted import LossAt, LossDuring, Script, ScriptedDevice


def run(text: str, script: Script | None = None, budget: int = 10_000
        ) -> tuple[RunResult, ScriptedDevice]:
    analysis = analyze(text)
    assert not analysis.has_errors, analysis.diagnostics
    device = ScriptedDevice(script)
    return interpret(analysis.program, device, budget), device


def variables(text: str, script: Script | None = None) -> dict[str, int]:
    result, _ = run(text, script)
    assert result.fault is None, result.fault
    return {name: value for name, value in result.named().items() if value}


def commands(device: ScriptedDevice) -> list[str]:
    return [" ".join([entry.call, *map(str, entry.args)]) for entry in device.trace]


# Arithmetic ---------------------------------------------------------------------------


def test_results_wrap_at_both_ends() -> None:
    assert variables("A=32767+1; B=-32768-1; C=32767; C++; D=-32768; D--; E=$FFFF; F=$8000"
                     ) == {"A": -32768, "B": 32767, "C": -32768, "D": 32767, "E": -1,
                           "F": -32768}


def test_expressions_run_strictly_left_to_right() -> None:
    # C=a<3+b>6+C is (((a<<3)+b)>>6)+C, not a<<(3+b) ...
    assert variables("a=5; b=300; C=7; C=a<3+b>6+C") == {"a": 5, "b": 300, "C": 12}
    assert variables("A=2+3&4|1^7-1") == {"A": 1}  # 5, 4, 5, 2, 1


def test_shift_counts_follow_the_spec() -> None:
    # B, E and H are 0: a left shift by 16 or more, a right shift of a positive value
    # by 16 or more, and -1 shifted left by 32768 (a right shift by -32768).
    assert variables("A=1<15; B=1<16; C=-1>15; D=-1>16; E=7>100; F=-8>-2; G=3<-1; "
                     "N=-32768; H=-1>N; I=-1<N; J=$4000>14; K=-7>1") == {
        "A": -32768, "C": -1, "D": -1, "F": -32, "G": 1, "N": -32768, "I": -1, "J": 1,
        "K": -4}


@settings(max_examples=200, deadline=None)
@given(st.integers(-32768, 32767), st.lists(
    st.tuples(st.sampled_from("+-&|^<>"), st.integers(-32768, 32767)), max_size=6))
def test_any_expression_matches_an_independent_model(
    first: int, steps: list[tuple[str, int]],
) -> None:
    text = f"A={first}" + "".join(f"{op}{value}" for op, value in steps)
    expected = first
    for op, value in steps:
        expected = operate(op, expected, value)
    assert variables(text).get("A", 0) == expected


# Control flow -------------------------------------------------------------------------


def test_conditional_jumps_compare_with_zero_signed() -> None:
    text = ("A=$FFFF; ?A<#10; B=1\n:10 ?A>#20; C=1\n:20 Z=0; ?Z=#30; D=1\n:30 E=1\n")
    assert variables(text) == {"A": -1, "C": 1, "E": 1}


def test_a_counted_loop_and_end_in_mid_line() -> None:
    assert variables("N=5\n:10 S=S+N; N--; ?N>#10\n(END); S=0\n") == {"S": 15}


def test_running_off_the_end_ends_the_program() -> None:
    result, device = run("(MOV 3,3)")
    assert result.fault is None and commands(device) == ["MOV 3 3"]


# Calls ----------------------------------------------------------------------------------


def test_sensing_calls_write_their_reserved_variables_and_return_results() -> None:
    script = Script(images=(ImageReading(180, 130, 90, -4),), odometry=(Odometry(50, 52, 48),),
                    camera=(392,), ultrasonic={"B": (77,)}, ports={5: (200,)},
                    after_last="repeat")  # FZI reads zeros
    assert variables("A=(IMG)-180; B=(KYO); (FZI); C=(CAM R)+(ULT B); D=(INP 5)",
                     script) == {"w": 180, "x": 130, "y": 90, "z": -4, "B": 50, "u": 52,
                                 "v": 48, "C": 469, "D": 200}


def test_variable_arguments_reach_the_device() -> None:
    _, device = run("L=-12; R=12; (MOV L,R); P=784; (CAM P P); (CAM A 90)")
    assert commands(device) == ["MOV -12 12", "CAM P 784", "CAM A 90"]


# Lost lines (Table 4) ---------------------------------------------------------------------

HANDLERS = ":96 H=96; (END)\n:97 H=97; (END)\n:98 H=98; (END)\n:99 H=99; (END)\n"


def traced(mode: int, motion: str, losses: tuple[LossAt | LossDuring, ...] = (LossAt(250),)
           ) -> tuple[RunResult, ScriptedDevice]:
    return run(f"(TRC {mode}); {motion}; (TIM 5); A=1\n(END)\n" + HANDLERS,
               Script(losses=losses))


def test_modes_2_and_3_jump_to_their_handlers_for_mov_and_mvi() -> None:
    expected = {(2, "MOV"): 98, (2, "MVI"): 99, (3, "MOV"): 96, (3, "MVI"): 97}
    for (mode, command), handler in expected.items():
        motion = "(MOV 2,2)" if command == "MOV" else "(MVI 2,2,10)"  # the MVI takes 1 s
        result, device = traced(mode, motion)
        named = result.named()
        assert (named["H"], named["A"]) == (handler, 0), (mode, command)
        assert device.trace[-1].call == "LINE LOST" and device.trace[-1].time == 250
        # The MVI returned at the loss: the TIM never ran.
        assert ("TIM 5" in commands(device)) == (command == "MOV")


def test_modes_0_and_1_do_not_jump() -> None:
    for mode in (0, 1):
        for motion in ("(MOV 2,2)", "(MVI 2,2,10)"):
            result, _ = traced(mode, motion)
            assert (result.named()["H"], result.named()["A"]) == (0, 1)


def test_a_loss_without_motion_does_not_jump() -> None:
    for motion in ("(MOV 0,0)", "(MVI 2,2,1)"):  # the MVI is done after 100 ms
        result, _ = traced(3, motion)
        assert result.named()["A"] == 1


def test_a_loss_during_an_operand_call_abandons_its_statement() -> None:
    result, device = run("(TRC 3); (MOV 3,3)\n:10 A=(IMG)-180; B++; ?A<#10\n(END)\n"
                         ":96 (MOV 0,0)\n", Script(losses=(LossAt(350),), after_last="repeat"))
    assert result.fault is None
    # IMG at 0, 100, 200, 300 ms; the line is lost during the fourth, before A is written.
    assert result.named()["B"] == 3
    assert result.named()["A"] == -180
    assert commands(device)[-2:] == ["LINE LOST 3", "MOV 0 0"]


def test_the_tracing_mode_persists_across_a_handler_jump() -> None:
    text = ("(TRC 3); (MOV 1,1); (TIM 10)\n(END)\n"
            ":96 C++; D=C-2; ?D=#97; (MOV 1,1); (TIM 10)\n:97 (MOV 0,0)\n")
    result, device = run(text, Script(losses=(LossAt(500), LossAt(1200))))
    assert result.named()["C"] == 2
    assert commands(device).count("LINE LOST 3") == 2


# Faults ---------------------------------------------------------------------------------


def fault_of(text: str, script: Script | None = None, budget: int = 10_000
             ) -> tuple[FaultKind, str, int | None, list[str]]:
    result, device = run(text, script, budget)
    assert result.fault is not None
    return result.fault.kind, result.fault.message, result.fault.line, commands(device)


def test_a_variable_argument_out_of_range_stops_the_vehicle_then_faults() -> None:
    kind, message, line, trace = fault_of("(MOV 3,3)\nS=13\nA=1; (MOV S,0); B=1\n")
    assert (kind, line) == (FaultKind.ARGUMENT_RANGE, 3)
    assert message == "argument l of (MOV) is 13 (the value of S), outside -12..12"
    assert trace == ["MOV 3 3", "STOP"]


def test_a_missing_handler_is_a_fault_on_the_line_of_the_interrupted_call() -> None:
    kind, message, line, trace = fault_of("(TRC 2)\n(MOV 1,1)\n(TIM 10)\n",
                                          Script(losses=(LossAt(100),)))
    assert (kind, line) == (FaultKind.MISSING_HANDLER, 3)
    assert ":98" in message and "mode 2" in message
    assert trace[-1] == "STOP"


def test_the_budget_counts_statements_and_is_checked_at_jumps_and_calls() -> None:
    result, device = run("A=0\n:10 A++\n#10\n", budget=7)
    assert result.fault is not None
    # Statements 1 (A=0), 2-3, 4-5, 6-7 pass; the jump that is statement 9 faults.
    assert (result.fault.kind, result.fault.line) == (FaultKind.BUDGET, 3)
    assert (result.named()["A"], commands(device)) == (4, ["STOP"])
    kind, _, line, trace = fault_of("A=1; B=2\n(FRE)\n", budget=2)
    assert (kind, line, trace) == (FaultKind.BUDGET, 2, ["STOP"])  # FRE never ran
    assert run("A=1; B=2; C=3; (END)", budget=1)[0].fault is None


def test_a_device_error_is_a_fault() -> None:
    kind, message, line, trace = fault_of("(MOV 1,1)\n(MVI 3,-3,10)\n")
    assert (kind, line) == (FaultKind.DEVICE, 2)
    assert "would never end" in message
    assert trace == ["MOV 1 1", "MVI 3 -3 10", "STOP"]


def test_programs_with_errors_are_not_run() -> None:
    for text, problem in [("#10\n", "#10"), ("A=(MOV 1,1)\n", "returns no value"),
                          (":10 A=1\n:10 B=1\n", "defined twice"), ("A=1+\n", "syntax"),
                          ("(XYZ)\n", "not a built-in"), ("A=70000\n", "16 bits")]:
        program, _ = parse_program(text)
        try:
            interpret(program, ScriptedDevice())
        except NotRunnable as refused:
            assert problem in str(refused), text
        else:
            raise AssertionError(f"{text!r} ran")
