"""The program generators of compiler/strategies.py: what they promise holds, and they
cover the whole language."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from hypothesis import HealthCheck, Phase, find, given, settings
from hypothesis import strategies as st

from rl1.compiler.analysis import analyze
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.parser import parse_line, parse_program
from rl1.compiler.interpreter import interpret
from rl1.compiler.strategies import OPERATORS, Run, checked_programs, lines, programs, runs
from rl1.vm.device import FuzzyReading, ImageReading, Odometry
from rl1.vm.language import BUILTINS
from rl1.vm.scripted import LossAt, LossDuring, Script, ScriptedDevice, parse_script

ALL_FORMS = {f"call {b.mnemonic} {form.selector}" for b in BUILTINS.values()
             for form in b.forms}


def constructs(text: str) -> set[str]:
    """Names for the constructs a source text uses, for coverage checks."""
    program, _ = parse_program(text)
    found = set()
    for node in ast.walk(program):
        found.add(type(node).__name__)
        if isinstance(node, ast.BinaryStep):
            found.add(f"op {node.op}")
            if isinstance(node.operand, ast.Call):
                found.add("call operand")
            if node.op in "<>" and isinstance(node.operand, ast.Const):
                count = node.operand.value
                found.add("shift by < 0" if count < 0 else "shift by >= 16" if count >= 16
                          else "shift by 0..15")
        elif isinstance(node, ast.CondJump):
            found.add(f"relation {node.relation}")
        elif isinstance(node, ast.IncDec):
            found.add(f"step {node.step}")
        elif isinstance(node, ast.Call):
            selector = node.args[0] if node.args and isinstance(node.args[0], ast.Selector) \
                else None
            found.add(f"call {node.mnemonic} {selector.letter if selector else None}")
            found.update("variable argument" for arg in node.args if isinstance(arg, ast.Var))
        elif isinstance(node, ast.Const):
            found.add("hex" if node.hex else "negative" if node.value < 0 else "decimal")
            if node.value in (32767, -32768):
                found.add("16-bit edge")
        elif isinstance(node, ast.Comment) and not node.text.isascii():
            found.add("non-ASCII comment")
        elif isinstance(node, ast.LabelDef) and node.number in range(96, 100):
            found.add(f"handler :{node.number}")
    found.update(name for name, present in (
        ("tab", "\t" in text), ("CR LF", "\r\n" in text),
        ("empty statement", any(";;" in line or line.strip().endswith(";")
                                for line in text.splitlines())),
    ) if present)
    return found


def coverage(strategy: st.SearchStrategy[str], examples: int) -> set[str]:
    seen: set[str] = set()

    @settings(max_examples=examples, database=None, derandomize=True, deadline=None)
    @given(strategy)
    def collect(text: str) -> None:
        seen.update(constructs(text))

    collect()
    return seen


def describe(text: str) -> Callable[[], str]:
    return lambda: "\n".join(f"{n:3} {line}" for n, line in enumerate(text.splitlines(), 1))


# What each strategy promises ----------------------------------------------------------


@settings(max_examples=300, deadline=None)
@given(lines())
def test_lines_parse_without_a_diagnostic(line: str) -> None:
    parsed, diagnostics = parse_line(line, 1)
    assert diagnostics == [] and parsed.ok
    assert "\r" not in line and "\n" not in line


@settings(max_examples=100, deadline=None)
@given(programs())
def test_programs_parse_without_a_diagnostic(text: str) -> None:
    _, diagnostics = parse_program(text)
    assert diagnostics == []


@settings(max_examples=100, deadline=None)
@given(checked_programs())
def test_checked_programs_pass_the_checker_without_errors(text: str) -> None:
    analysis = analyze(text)
    errors = [f"{d.span.line}: {d.code} {d.message}" for d in analysis.diagnostics
              if d.is_error]
    assert errors == [], describe(text)()


@st.composite
def scripts(draw: st.DrawFn) -> Script:
    """Sensor readings and line losses for the scripted device."""
    small = st.integers(-300, 300)
    return Script(
        images=tuple(draw(st.lists(st.builds(ImageReading, st.integers(0, 5000), small,
                                             small, small), max_size=4))),
        odometry=tuple(draw(st.lists(st.builds(Odometry, small, small, small), max_size=3))),
        camera=tuple(draw(st.lists(st.integers(0, 784), max_size=3))),
        ultrasonic={"A": tuple(draw(st.lists(st.integers(0, 500), max_size=3)))},
        ports={3: tuple(draw(st.lists(st.integers(0, 255), max_size=3)))},
        fuzzy=tuple(draw(st.lists(st.builds(FuzzyReading, small, small), max_size=2))),
        losses=tuple(draw(st.lists(st.one_of(
            st.builds(LossAt, st.integers(0, 30_000)),
            st.builds(LossDuring, st.sampled_from(("MOV", "MVI")), st.integers(1, 3),
                      st.integers(0, 2_000)),
        ), max_size=3))),
    )


@settings(max_examples=100, deadline=None)
@given(checked_programs(), scripts())
def test_checked_programs_end_without_a_fault_whatever_the_device_does(
        text: str, script: Script) -> None:
    program, _ = parse_program(text)
    result = interpret(program, ScriptedDevice(script), budget=100_000)
    assert result.fault is None, describe(text)()


# Coverage -----------------------------------------------------------------------------


def test_lines_and_programs_cover_the_whole_syntax() -> None:
    expected = ALL_FORMS | {f"op {op}" for op in OPERATORS} | {
        "Assign", "IncDec", "Goto", "CondJump", "CallStmt", "LabelDef", "Comment",
        "relation =", "relation <", "relation >", "step ++", "step --", "call operand",
        "variable argument", "hex", "negative", "decimal", "non-ASCII comment", "tab",
        "empty statement", "CR LF", "shift by < 0", "shift by >= 16",
    }
    # Hypothesis mixes the literals of the modules loaded so far into what it draws, so
    # which ones a run covers shifts as the project grows: 600 examples leave a margin.
    assert expected - coverage(programs(max_lines=8), 600) == set()


def test_checked_programs_cover_every_form_operator_edge_and_handler() -> None:
    expected = ALL_FORMS | {f"op {op}" for op in OPERATORS} | {
        "relation =", "relation <", "relation >", "step ++", "step --",
        "call operand", "variable argument", "hex", "negative", "shift by < 0",
        "shift by >= 16", "16-bit edge", "handler :96", "handler :97", "handler :98",
        "handler :99",
    }
    assert expected - coverage(checked_programs(), 200) == set()


def what_a_run_does(case: Run) -> set[str]:
    """What a run of `runs()` shows when interpreted: how it ends, and whether a handler
    was entered, and entered again."""
    analysis = analyze(case.source)
    assert not analysis.has_errors, describe(case.source)()
    device = ScriptedDevice(parse_script(case.script))
    result = interpret(analysis.program, device, budget=20_000)
    losses = sum(entry.call == "LINE LOST" for entry in device.trace)
    return {result.fault.kind.code if result.fault else "ok",
            *(["handler entered"] if losses else []), *(["entered again"] * (losses > 1))}


@pytest.mark.parametrize("outcome", ["ok", "argument-range", "missing-handler",
                                     "device-error", "handler entered", "entered again"])
def test_runs_wait_on_sensors_enter_handlers_and_fault(outcome: str) -> None:
    # Each is common enough that a few hundred runs show it (not shrunk: any will do).
    search = settings(max_examples=500, phases=[Phase.generate], database=None,
                      deadline=None, suppress_health_check=list(HealthCheck))
    find(runs(), lambda case: outcome in what_a_run_does(case), settings=search)
