"""The optimizer keeps what spec/optimization.md says is observable: on generated
programs and sensor scripts, the AST interpreter and the VM at every level agree on the
trace, the ending and the variables, and no optimized run executes more instructions
than -O0 up to any call."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings

from rl1.compiler.differential import AstEngine, VmEngine, judge
from rl1.compiler.strategies import Run, checked_programs, runs

ENGINES = (AstEngine(), VmEngine(0), VmEngine(1), VmEngine(2))
BUDGET = 20_000


# Two halves of the same property, so that pytest-xdist runs them side by side.
@settings(max_examples=500, deadline=None, suppress_health_check=list(HealthCheck))
@given(runs())
def test_every_level_runs_as_the_interpreter_does(case: Run) -> None:
    assert judge(case, ENGINES, BUDGET).problems == []


@settings(max_examples=500, deadline=None, suppress_health_check=list(HealthCheck))
@given(runs(max_blocks=3))
def test_small_programs_run_the_same_at_every_level(case: Run) -> None:
    assert judge(case, ENGINES, BUDGET).problems == []


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(checked_programs())
def test_programs_that_always_end_end_the_same_at_every_level(source: str) -> None:
    verdict = judge(Run(source, {}), ENGINES, BUDGET)
    assert verdict.problems == []
    assert not any(observation.ran_away for observation in verdict.observations.values())
