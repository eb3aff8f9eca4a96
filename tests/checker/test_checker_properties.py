"""Properties of the checker over generated programs: it never fails, its per-line part is
exactly the per-line rules, and its tracing and safety warnings cover what the
interpreter does with a device that loses the line at random."""

from __future__ import annotations

import re

from hypothesis import given, settings
from hypothesis import strategies as st

from rl1.compiler.analysis import analyze, diagnose
from rl1.compiler.checker import check, check_line
from rl1.compiler.checker.lines import check_line as per_line_rule
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.interpreter import interpret
from rl1.compiler.strategies import programs
from rl1.vm.faults import FaultKind
from rl1.vm.scripted import LossAt, LossDuring, Script, ScriptedDevice

PER_LINE_CODES = {"E0201", "E0202", "W0402", "E0501", "W0502", "E0503", "E0504", "E0505",
                  "E0506", "E0507", "E0508"}

# Text close enough to RL/I to reach the checker's corners: its characters and words.
rl1_text = st.lists(st.sampled_from([
    *"ABCMOVxyzuvs@:#?=+-&|^<>(),; $0123456789'\n", "MOV", "MVI", "TRC", "END", "IMG",
    "CAM", "ULT", "(END)", ":96", "#10", ":10 ", "(TRC 3)", "(MOV 3,3)", "\n"]),
    max_size=80).map("".join)


@settings(max_examples=300, deadline=None)
@given(st.one_of(rl1_text, st.text(max_size=100), programs()))
def test_checking_never_fails(text: str) -> None:
    analyze(text)


@settings(max_examples=150, deadline=None)
@given(st.one_of(rl1_text, programs()))
def test_the_per_line_part_is_exactly_the_per_line_rules(text: str) -> None:
    program, _ = parse_program(text)
    whole = [d for d in check(program) if d.code in PER_LINE_CODES]
    lines = [d for line in program.lines for d in check_line(line)]
    assert sorted(whole, key=repr) == sorted(lines, key=repr)
    assert check_line is per_line_rule
    assert all(d.code in PER_LINE_CODES for d in lines)


# Against the interpreter -------------------------------------------------------------


@st.composite
def traced_programs(draw: st.DrawFn) -> str:
    """Programs that move in every tracing mode with forward jumps only (so they end),
    defining a random subset of the handlers, each of which ends."""
    statements = st.sampled_from([
        "(TRC 0)", "(TRC 1)", "(TRC 2)", "(TRC 3)", "(TRC M)", "(MOV 3,3)", "(MOV 0,0)",
        "(MOV A,0)", "(MVI 2,2,40)", "(MVI 1,1,0)", "(FRE)", "(HLD)", "(TIM 3)", "(IMG)",
        "A=(IMG)-150", "M=(ULT A)&3", "(END)",
    ])
    lines = []
    for number in range(draw(st.integers(1, 6))):
        body = draw(st.lists(statements, min_size=1, max_size=4))
        if number == 0:  # trace more often than not
            body.insert(0, draw(st.sampled_from(["(TRC 2)", "(TRC 3)", "(TRC 1)"])))
        if draw(st.booleans()):
            body.append(f"?A>#{(number + 1) * 10:02d}")
        lines.append(f":{number * 10:02d} " + "; ".join(body))
    lines.append(f":{len(lines) * 10:02d}")
    for label in draw(st.sets(st.sampled_from([96, 97, 98, 99]))):
        handler = draw(st.lists(statements.filter(lambda s: s != "(END)"), max_size=2))
        lines.append(f":{label} " + "; ".join([*handler, "(END)"]))
    return "\n".join(lines) + "\n"


losses = st.lists(st.one_of(
    st.builds(LossAt, st.integers(0, 3_000)),
    st.builds(LossDuring, st.sampled_from(("MOV", "MVI")), st.integers(1, 3),
              st.integers(1, 500)),
), min_size=1, max_size=3)


def _motion_left_on(device: ScriptedDevice) -> bool:
    """Whether the last motion command the device got was a non-zero MOV."""
    moving = False
    for entry in device.trace:
        if entry.call == "MOV":
            moving = any(entry.args)
        elif entry.call in ("MVI", "FRE", "HLD"):
            moving = False
    return moving


@settings(max_examples=300, deadline=None)
@given(traced_programs(), losses, st.integers(-3, 3))
def test_every_missing_handler_at_run_time_was_warned_about(
        text: str, lost: list[LossAt | LossDuring], mode: int) -> None:
    program, _ = parse_program(text.replace("M=(ULT A)&3", f"M={mode}"))
    warned = {d.message.split("`")[1] for d in check(program) if d.code == "W0301"}
    result = interpret(program, ScriptedDevice(Script(losses=tuple(lost))), budget=10_000)
    if result.fault is not None and result.fault.kind is FaultKind.MISSING_HANDLER:
        label = re.findall(r":\d\d", result.fault.message)[-1]
        assert label in warned, (text, result.fault)


@settings(max_examples=200, deadline=None)
@given(traced_programs())
def test_every_run_ending_while_moving_was_warned_about(text: str) -> None:
    program, _ = parse_program(text)
    device = ScriptedDevice(Script())  # the line is never lost
    result = interpret(program, device, budget=10_000)
    if result.fault is None and _motion_left_on(device):
        assert "W0701" in {d.code for d in check(program)}, text


@settings(max_examples=400, deadline=None)
@given(st.one_of(rl1_text, st.text(max_size=100), programs(), traced_programs()))
def test_the_check_without_the_tree_gives_the_same_diagnostics(text: str) -> None:
    """`rl1c check`'s path (checker/streaming.py) against the check on the tree, which
    the compiler runs: the same diagnostics, in the same order."""
    expected = analyze(text).diagnostics
    assert diagnose(text) == expected
    assert [repr(d) for d in diagnose(text)] == [repr(d) for d in expected]
