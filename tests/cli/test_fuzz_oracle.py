"""The oracle of `rl1c fuzz` (compiler/differential.py): what compares when a run meets
the watchdog (spec/optimization.md, sections 3 and 5), engines at a level of their own,
and every engine driving the device as `rl1c run` does."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import pytest
from support import ROOT

from rl1.compiler.differential import (
    INVARIANT,
    SAME_CODE,
    SHARED_PREFIX,
    Engine,
    Observation,
    VmEngine,
    differences,
    engine_named,
    judge,
)
from rl1.compiler.strategies import Run
from rl1.vm import ilc, isa

RL1C = shlex.quote(str(Path(sys.executable).with_name("rl1c")))
ENGINES = ROOT / "tests/support/engines"
LAZY = f"exec:sh {shlex.quote(str(ENGINES / 'lazy.sh'))}"
EARLY_WATCHDOG = (f"exec:sh {shlex.quote(str(ENGINES / 'early_watchdog.sh'))} {RL1C} "
                  "{ilc} {sensors} {budget}")
RL1C_RUN = f"exec:{RL1C} run {{ilc}} --sensors {{sensors}} --budget {{budget}} --format json"
BUDGET = 20_000

# About 400 instructions at -O0, well inside the budget; a hundredth of it is not.
COUNTED = "B=100\n:10 A=A+3; B--; ?B>#10\n(MOV 3,3); (END)\n"
FOREVER = ":10 A=A+1; #10\n"


def engines(*names: str) -> list[Engine]:
    found = [engine_named(name) for name in names]
    assert all(found), names
    return [engine for engine in found if engine is not None]


def run(trace: int, *, ran_away: bool, a: int = 0) -> Observation:
    status = {"code": "budget", "line": 1} if ran_away else {"code": "ok", "line": None}
    return Observation({"status": status, "variables": {"A": a}, "trace": [
        {"time": 0, "call": "MOV", "args": [3, index]} for index in range(trace)]})


def test_an_engine_that_runs_nothing_and_says_watchdog_disagrees() -> None:
    # It agreed with everything: a run ending on the budget compared only the traces'
    # shared prefix, here none.
    verdict = judge(Run(COUNTED, {}), engines("vm-O0", LAZY), BUDGET)
    lazy = engines(LAZY)[0].name
    assert f"{lazy}: met the watchdog, where vm-O0 ended after " in "\n".join(verdict.problems)
    assert f"{lazy}: ending: ended normally / fault budget" in verdict.problems


def test_the_interpreter_as_reference_holds_a_lazy_engine_to_the_minus_o0_run() -> None:
    # The interpreter counts statements, so the -O0 VM, run for the purpose, says
    # whether the program ends within the budget.
    verdict = judge(Run(COUNTED, {}), engines("ast", LAZY), BUDGET)
    assert set(verdict.observations) == {"ast", engines(LAZY)[0].name}
    assert any("met the watchdog, where vm-O0 ended" in line for line in verdict.problems)


def test_a_watchdog_that_fires_too_early_disagrees_where_minus_o0_ends() -> None:
    verdict = judge(Run(COUNTED, {}), engines("vm-O0", EARLY_WATCHDOG), BUDGET)
    early = engines(EARLY_WATCHDOG)[0].name
    assert verdict.observations[early].ran_away
    assert f"{early}: ending: ended normally / fault budget at line 2" in verdict.problems


def test_on_the_minus_o0_file_an_engine_counts_the_instructions_minus_o0_does() -> None:
    # Both meet the watchdog; on the same code they must meet it at the same point.
    verdict = judge(Run(FOREVER, {}), engines("vm-O0", EARLY_WATCHDOG), BUDGET)
    early = engines(EARLY_WATCHDOG)[0].name
    assert verdict.observations["vm-O0"].ran_away and verdict.observations[early].ran_away
    assert any(line.startswith(f"{early}: variables: A ") for line in verdict.problems)


def test_an_optimized_run_may_go_past_the_minus_o0_watchdog() -> None:
    unoptimized = VmEngine(0).run(Run(COUNTED, {}), BUDGET).executed
    optimized = VmEngine(2).run(Run(COUNTED, {}), BUDGET).executed
    assert unoptimized is not None and optimized is not None and optimized < unoptimized
    budget = (unoptimized + optimized) // 2
    verdict = judge(Run(COUNTED, {}), engines("ast", "vm-O0", "vm-O2"), budget)
    assert verdict.observations["vm-O0"].ran_away
    assert not verdict.observations["vm-O2"].ran_away
    assert verdict.problems == []


@pytest.mark.parametrize(("rule", "reference", "other", "differs"), [
    (SAME_CODE, run(3, ran_away=True), run(3, ran_away=True, a=1), True),
    (SAME_CODE, run(3, ran_away=True), run(3, ran_away=False), True),
    (INVARIANT, run(3, ran_away=True), run(5, ran_away=False, a=9), False),
    (INVARIANT, run(3, ran_away=True), run(2, ran_away=True), True),  # stopped sooner
    (INVARIANT, run(3, ran_away=False), run(3, ran_away=True), True),
    (SHARED_PREFIX, run(3, ran_away=True), run(2, ran_away=True, a=4), False),
    (SHARED_PREFIX, run(3, ran_away=False), run(3, ran_away=False, a=4), True),
])
def test_what_compares_when_a_run_meets_the_watchdog(rule: str, reference: Observation,
                                                     other: Observation, differs: bool) -> None:
    assert bool(differences(reference, other, rule)) == differs  # type: ignore[arg-type]


# Engines at a level -----------------------------------------------------------------------


@pytest.mark.parametrize(("name", "level"), [("exec:x {ilc}", 0), ("exec-O0:x", 0),
                                              ("exec-O1:x", 1), ("exec-O2:run {ilc}", 2)])
def test_an_exec_engine_names_its_level(name: str, level: int) -> None:
    engine = engine_named(name)
    assert engine is not None and engine.level == level
    assert engine.name == (name if level else "exec:" + name.partition(":")[2])


@pytest.mark.parametrize("name", ["exec-O3:x", "exec-O:x", "exec-O2:", "exec-O2: "])
def test_an_exec_engine_at_no_level_is_no_engine(name: str) -> None:
    assert engine_named(name) is None


@pytest.mark.parametrize(("level", "minor"), [(0, 1), (2, 2)])
def test_an_exec_engine_at_minus_o2_gets_the_superinstructions(tmp_path: Path, level: int,
                                                             minor: int) -> None:
    # A = B, a move, and a counted loop's decrement and branch: DJGT at -O2 (format 1.2).
    source = "A=B\nC=3\n:10 D=D+A; C--; ?C>#10\n(END)\n"
    given = tmp_path / "given.ilc"
    prefix = "exec:" if level == 0 else f"exec-O{level}:"
    engine = engine_named(f"{prefix}cp {{ilc}} {shlex.quote(str(given))} && "
                          + RL1C_RUN.removeprefix("exec:"))
    assert engine is not None
    observation = engine.run(Run(source, {}), BUDGET)
    assert differences(VmEngine(level).run(Run(source, {}), BUDGET), observation,
                       SAME_CODE) == []
    data = given.read_bytes()
    assert ilc.read_header(data).minor == minor
    assert (isa.code_minor(ilc.decode(data).code) == 2) == (level == 2)


# Line losses after an instruction count ---------------------------------------------------

# The line is lost after instruction 2 (the MOV), taken at the jump: the handler runs.
LOST_BETWEEN_CALLS = Run("(TRC 3); (MOV 3,3)\nA=50; #10\n(END)\n:10 (MOV 3,3); (END)\n"
                         ":96 A=4; B=-46; C=4; (MOV 3,3); (END)\n",
                         {"line_lost": [{"instruction": 2}]})


def test_the_built_in_vm_loses_the_line_after_an_instruction_count_as_rl1c_run_does() -> None:
    # vm-O0 ran machine.run(), which ignores such losses: TRC MOV MOV and A=50, where
    # `rl1c run` gave TRC MOV LINE LOST MOV and A=4.
    verdict = judge(LOST_BETWEEN_CALLS, engines("vm-O0", RL1C_RUN), BUDGET)
    assert verdict.problems == []
    [reference, rl1c_run] = verdict.observations.values()
    assert [entry["call"] for entry in reference.document["trace"]] == [
        "TRC", "MOV", "LINE LOST", "MOV"]
    assert {name: reference.document["variables"][name] for name in "ABC"} == {
        "A": 4, "B": -46, "C": 4}
    assert rl1c_run.commands() == reference.commands()


def test_with_losses_after_instruction_counts_only_engines_at_one_level_compare() -> None:
    # Optimized code runs fewer instructions, so the count names another point in it;
    # the interpreter counts statements and does not run such a script.
    verdict = judge(LOST_BETWEEN_CALLS, engines("ast", "vm-O0", "vm-O2", LAZY), BUDGET)
    assert set(verdict.observations) == {"vm-O0", "vm-O2", engines(LAZY)[0].name}
    assert verdict.problems and all(line.startswith("exec:") for line in verdict.problems)
