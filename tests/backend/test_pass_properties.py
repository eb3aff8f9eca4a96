"""Each optimizer pass alone keeps what spec/optimization.md says is observable, on
generated programs and sensor scripts, with the budget invariant against -O0; and what
the optimizer's rounds rely on to skip a pass: the passes it calls idempotent are (a
second run changes nothing), and a pass it says gives another no work gives none."""

from __future__ import annotations

from dataclasses import dataclass, replace

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rl1.compiler.analysis import analyze
from rl1.compiler.backend import ir, ir_text, optimize
from rl1.compiler.backend.codegen import generate
from rl1.compiler.backend.constants import fold_constants
from rl1.compiler.backend.control import simplify_control
from rl1.compiler.backend.copies import cancel_equal_operands, propagate_copies
from rl1.compiler.backend.dead_stores import remove_dead_stores
from rl1.compiler.backend.final_end import leave_out_final_end
from rl1.compiler.backend.lower import lower
from rl1.compiler.backend.peephole import rewrite_steps
from rl1.compiler.backend.signs import decide_branches
from rl1.compiler.backend.superinstructions import fuse
from rl1.compiler.backend.tails import merge_tails
from rl1.compiler.differential import (
    AstEngine,
    Observation,
    VmEngine,
    budget_violations,
    differences,
    judge,
)
from rl1.compiler.strategies import Run, runs, sensor_scripts
from rl1.vm import ilc
from rl1.vm.hardware import Blocking
from rl1.vm.machine import Machine
from rl1.vm.scripted import ScriptedDevice, parse_script, run_document
from rl1.vm.verifier import verify

BUDGET = 20_000


def decide_branches_after_control(program: ir.Program) -> ir.Program:
    """decide_branches where -O1 runs it: on IR whose jumps control.py has threaded, the
    only IR on which its negation finds a branch next to its jump."""
    return decide_branches(simplify_control(program))


def fuse_after_copies(program: ir.Program) -> ir.Program:
    """fuse where -O2 runs it: after copy propagation, which drops loads that it then
    makes again after the calls between (`I=(INP 2); (LMP 0); E=I-128`)."""
    return fuse(propagate_copies(program))


PASSES = (fold_constants, decide_branches, decide_branches_after_control, propagate_copies,
          cancel_equal_operands, remove_dead_stores, rewrite_steps, simplify_control, fuse,
          fuse_after_copies, merge_tails, leave_out_final_end)
# The passes whose work needs shapes that runs() seldom makes (shaped_runs below).
SHAPED_PASSES = (fuse, fuse_after_copies, merge_tails, leave_out_final_end)
# Not simplify_control: removing blocks can make jumps to thread that it saw as none.
IDEMPOTENT = (*sorted(optimize.IDEMPOTENT, key=lambda run_pass: run_pass.__name__), fuse)
NO_WORK = [(giver, receiver) for giver, receivers in optimize.GIVES_NO_WORK_TO.items()
           for receiver in sorted(receivers, key=lambda run_pass: run_pass.__name__)]


def lowered(source: str) -> ir.Program:
    return lower(analyze(source).program)


@dataclass(frozen=True)
class OnePassEngine:
    """The IR as lowered, then one pass, then the reference VM."""

    run_pass: optimize.Pass

    @property
    def name(self) -> str:
        return f"vm-{self.run_pass.__name__}"

    def run(self, case: Run, budget: int) -> Observation:
        program = self.run_pass(lowered(case.source))
        assert ir.validate(program) == []
        image = generate(program, "pass.rob")
        assert image.debug is not None  # its lines name a fault's line; 1.2 needs a digest
        image = replace(image, debug=replace(image.debug,
                                             source_digest=ilc.source_digest(case.source)))
        device = ScriptedDevice(parse_script(case.script))
        machine = Machine(verify(ilc.encode(image)), Blocking(device), budget)
        result = machine.run()
        return Observation(run_document(result, device.trace), machine.executed,
                           tuple(machine.call_counts))


@pytest.mark.parametrize("run_pass", PASSES, ids=lambda run_pass: run_pass.__name__)
@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
@given(case=runs(max_blocks=3))
def test_each_pass_alone_keeps_what_is_observable(run_pass: optimize.Pass, case: Run
                                                  ) -> None:
    unoptimized = VmEngine(0).run(case, BUDGET)
    optimized = OnePassEngine(run_pass).run(case, BUDGET)
    assert differences(unoptimized, optimized) == []
    assert budget_violations(unoptimized, optimized, BUDGET) == []


# Programs of the shapes the later passes look for, from short statements on a few
# variables (so that tails are often alike): an if-else whose ways end alike and join; a
# loop whose body ends as the code before it does; a branch on a variable written before
# moves, steps and calls; each on readings of the script, so that either way runs.
_NAMES = "BCDEF"


@st.composite
def _statement(draw: st.DrawFn) -> str:
    target, source = draw(st.sampled_from(_NAMES)), draw(st.sampled_from(_NAMES))
    return draw(st.sampled_from([
        f"{target}={source}", f"{target}={draw(st.integers(-3, 200))}",
        f"{target}={source}{draw(st.sampled_from('+-&<'))}{draw(st.integers(0, 3))}",
        f"{target}=A-{source}", f"{target}++", f"{target}--", "(TIM 1)",
        f"(OUT 1,{source})"]))


def _statements(draw: st.DrawFn, most: int = 3) -> str:
    return "; ".join(draw(st.lists(_statement(), max_size=most))) or "G++"


@st.composite
def _shaped_program(draw: st.DrawFn) -> str:
    tail, first, second = _statements(draw), _statements(draw), _statements(draw)
    relation = draw(st.sampled_from("=<>"))
    variable = draw(st.sampled_from("A" + _NAMES))
    shape = draw(st.sampled_from(("if-else", "loop", "branch")))
    if shape == "if-else":
        lines = [f"?{variable}{relation}#20", f"{first}; {tail}; #30", f":20 {second}; {tail}",
                 f":30 {_statements(draw)}"]
    elif shape == "loop":
        lines = [f"@=3; {tail}", f":10 {first}; @--; ?@=#20", f"{second}; {tail}; #10",
                 ":20 G++"]
    else:
        lines = [f":10 {variable}=A-{draw(st.integers(0, 3))}; {first}; ?{variable}"
                 f"{relation}#20", f"@--; {second}; ?@>#10", ":20 G++"]
    ending = draw(st.sampled_from(["(END)", "(MOV 0,0)", "(MOV 0,0); (END)"]))
    return "\n".join(["(TRC 0); @=2; A=(ULT A)", *lines, ending]) + "\n"


@st.composite
def shaped_runs(draw: st.DrawFn) -> Run:
    return Run(draw(_shaped_program()), draw(sensor_scripts()))


@pytest.mark.parametrize("run_pass", SHAPED_PASSES, ids=lambda run_pass: run_pass.__name__)
@settings(max_examples=80, deadline=None, suppress_health_check=list(HealthCheck))
@given(case=shaped_runs())
def test_each_later_pass_alone_keeps_what_is_observable_where_it_has_work(
        run_pass: optimize.Pass, case: Run) -> None:
    unoptimized = VmEngine(0).run(case, BUDGET)
    optimized = OnePassEngine(run_pass).run(case, BUDGET)
    assert differences(unoptimized, optimized) == []
    assert budget_violations(unoptimized, optimized, BUDGET) == []


@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(case=shaped_runs())
def test_every_level_runs_the_shaped_programs_as_the_interpreter_does(case: Run) -> None:
    engines = (AstEngine(), VmEngine(0), VmEngine(1), VmEngine(2))
    assert judge(case, engines, BUDGET).problems == []


@pytest.mark.slow  # a Hypothesis search inside, which the marker plugin cannot see
def test_the_shaped_programs_give_the_later_passes_work() -> None:
    """So that the property above tests them: each pass changes a good share."""
    @settings(max_examples=100, deadline=None, suppress_health_check=list(HealthCheck))
    @given(case=shaped_runs())
    def tally(case: Run) -> None:
        for run_pass in SHAPED_PASSES:
            before = ir_text.format_program(lowered(case.source))
            changed[run_pass] += ir_text.format_program(run_pass(lowered(case.source))) != before

    changed = dict.fromkeys(SHAPED_PASSES, 0)
    tally()
    assert all(count >= 10 for count in changed.values()), changed


@pytest.mark.parametrize("run_pass", IDEMPOTENT, ids=lambda run_pass: run_pass.__name__)
@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
@given(case=runs(max_blocks=3))
def test_a_second_run_of_the_pass_changes_nothing(run_pass: optimize.Pass, case: Run
                                                  ) -> None:
    once = ir_text.format_program(run_pass(lowered(case.source)))
    twice = ir_text.format_program(run_pass(run_pass(lowered(case.source))))
    assert twice == once


@pytest.mark.parametrize(("giver", "receiver"), NO_WORK,
                         ids=lambda run_pass: run_pass.__name__)
@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
@given(case=runs(max_blocks=3))
def test_a_pass_gives_no_work_to_those_the_optimizer_says(
        giver: optimize.Pass, receiver: optimize.Pass, case: Run) -> None:
    program = giver(settle(receiver, lowered(case.source)))
    before = ir_text.format_program(program)  # the receiver edits the program in place
    assert ir_text.format_program(receiver(program)) == before


def settle(run_pass: optimize.Pass, program: ir.Program) -> ir.Program:
    """The program after the pass, run until it changes nothing (decide_branches can
    find more on a second run)."""
    for _ in range(optimize.MAX_ROUNDS):
        before = ir_text.format_program(program)
        program = run_pass(program)
        if ir_text.format_program(program) == before:
            return program
    raise AssertionError(f"{run_pass.__name__} did not settle")


@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
@given(case=runs(max_blocks=3))
def test_an_optimized_program_optimizes_to_itself(case: Run) -> None:
    once = optimize.optimize(lowered(case.source), 1)
    assert ir_text.format_program(optimize.optimize(once, 1)) == ir_text.format_program(once)
