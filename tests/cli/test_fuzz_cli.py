"""`rl1c fuzz`: the built-in engines agree, an `exec:` engine speaks the protocol of
spec/optimization.md section 5, and a planted bug is found, shrunk and written down."""

from __future__ import annotations

import json
import shlex
import sys
from pathlib import Path

import pytest
from hypothesis import find
from support import ROOT
from support.cli import rl1c

from rl1.compiler import fuzz
from rl1.compiler.differential import Observation, differences, engine_named, judge
from rl1.compiler.frontend.source import split_lines
from rl1.compiler.strategies import Run

PYTHON = shlex.quote(sys.executable)
RL1C = shlex.quote(str(Path(sys.executable).with_name("rl1c")))
BROKEN_VM = f"exec:{PYTHON} {shlex.quote(str(ROOT / 'tests/support/broken_vm.py'))} " \
            "{ilc} {sensors} {budget}"


def test_the_built_in_engines_agree_and_the_summary_says_so() -> None:
    result = rl1c("fuzz", "--count", "25", "--seed", "5")
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("fuzz: 25 programs in ")
    assert "engines ast, vm-O0, vm-O1, vm-O2; seed 5: all agreed" in result.stdout


def test_a_long_campaign_is_many_searches_with_the_same_programs_for_a_seed(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # Each Hypothesis search keeps what it learnt of every run until it ends (a campaign
    # of 50,000 in one search grew past 10 GB), so a campaign is searches of BATCH runs.
    monkeypatch.setattr(fuzz, "BATCH", 4)
    engines = [engine_named("ast"), engine_named("vm-O0")]
    sources: list[list[str]] = [[], []]
    searches: list[int] = []

    def counted_find(*args: object, **kwargs: object) -> object:
        searches.append(1)
        return find(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(fuzz, "find", counted_find)
    for seen in sources:
        def judged(case: Run, *args: object, seen: list[str] = seen) -> object:
            seen.append(case.source)
            return judge(case, *args)  # type: ignore[arg-type]

        monkeypatch.setattr(fuzz, "judge", judged)
        outcome = fuzz.campaign([e for e in engines if e is not None], 20_000, count=10,
                                seconds=None, seed=7, progress=lambda programs, elapsed: None)
        assert outcome.programs == 10 and outcome.finding is None
    assert len(searches) == 2 * 3  # 4 + 4 + 2 programs, twice
    assert sources[0] == sources[1] and len(sources[0]) == 10


class _CrashesOnLess:
    """An engine whose compiler fails on any program with a `<` (a shift or a branch),
    as the optimizer once failed on a line map: a crash is a finding, not the end of
    the campaign."""

    name = "crashes"

    def run(self, case: Run, budget: int) -> Observation:
        if "<" in case.source:
            raise ValueError("line entry (10, 5): lines must not decrease")
        return engine_named("ast").run(case, budget)  # type: ignore[union-attr]


def test_an_engine_that_crashes_is_a_finding_shrunk_like_a_disagreement(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 40)
    reference = engine_named("ast")
    assert reference is not None
    outcome = fuzz.campaign([reference, _CrashesOnLess()], 20_000, count=300,
                            seconds=None, seed=3, progress=lambda programs, elapsed: None)
    assert outcome.finding is not None
    assert "crashes: crashed: ValueError: line entry (10, 5): lines must not decrease" \
        in outcome.finding.verdict.problems
    assert len(split_lines(outcome.finding.case.source)) <= 5


def test_rl1c_run_itself_is_an_exec_engine_as_the_spec_shows(tmp_path: Path) -> None:
    command = f"exec:{RL1C} run {{ilc}} --sensors {{sensors}} --budget {{budget}} --format json"
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", command, "--count", "4",
                  "--seed", "2", "--out", str(tmp_path))
    assert result.exit_code == 0, result.output
    assert "all agreed" in result.stdout


def test_a_planted_shift_bug_is_found_and_shrunk_to_a_few_lines(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # A bound in runs, not seconds, so that a loaded machine shrinks as far as an idle
    # one; then deleting lines does the rest.
    monkeypatch.setattr(fuzz, "SHRINK_SECONDS", 600.0)
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 40)
    out = tmp_path / "found"
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", BROKEN_VM, "--count", "300",
                  "--seed", "1", "--out", str(out))
    assert result.exit_code == 1, result.output
    assert "the engines disagree (reference: vm-O0)" in result.stdout
    program = (out / "program.rob").read_text(encoding="utf-8")
    # Which run disagrees first depends on Hypothesis' draws, which mix in the literals
    # of the modules the suite has loaded: a loop around the shift (5 lines) is as small
    # as some of those runs go.
    assert 1 <= len(split_lines(program)) <= 5, program
    assert "<" in program  # a left shift, by a negative count
    runs = [json.loads(path.read_text(encoding="utf-8")) for path in sorted(out.glob("run-*"))]
    assert len(runs) == 2 and runs[0]["variables"] != runs[1]["variables"]
    assert "variables: " in result.stdout and f"sh {out}/replay.sh" in result.stdout
    replay = (out / "replay.sh").read_text(encoding="utf-8")
    assert "rl1c run program-O0.ilc --sensors program.sensors.json" in replay
    assert {"program.sensors.json", "program-O0.ilc", "replay.sh"} <= {
        path.name for path in out.iterdir()}


def test_an_engine_that_prints_no_run_disagrees(tmp_path: Path) -> None:
    result = rl1c("fuzz", "--engine", "ast", "--engine", "exec:echo not json", "--count", "3",
                  "--seed", "4", "--out", str(tmp_path))
    assert result.exit_code == 1
    assert "ending: ended normally / fault no-run" in result.stdout \
        or "fault no-run" in result.stdout


@pytest.mark.parametrize(("args", "message"), [
    (["--engine", "vm-O7", "--engine", "ast"], "unknown engine 'vm-O7'"),
    (["--engine", "ast"], "give at least two different engines"),
    (["--engine", "ast", "--engine", "ast"], "give at least two different engines"),
    (["--count", "5", "--time", "5"], "give --count or --time, not both"),
    (["--count", "0"], "argument --count: expected a whole number of at least 1"),
    (["--seed", "x"], "argument --seed: expected a whole number"),
])
def test_bad_options_are_usage_errors(args: list[str], message: str) -> None:
    result = rl1c("fuzz", *args)
    assert result.exit_code == 2
    assert message in result.stderr


def test_runs_are_compared_on_what_the_protocol_names_only() -> None:
    plain = Observation({"status": "ok", "variables": {}, "trace": [
        {"time": 0, "call": "MOV", "args": [3, 3]}]})  # the first form of the protocol
    annotated = Observation({
        "status": {"code": "ok", "exit_status": 0, "message": "the program ended",
                   "line": None},
        "variables": {}, "trace": [
            {"time": 0, "call": "LINE LOST", "args": [0], "line": 1, "during": None,
             "effect": "no-motion", "handler": None},
            {"time": 0, "call": "MOV", "args": [3, 3], "line": 2}]})
    assert differences(plain, annotated) == []
    moved = Observation({**annotated.document, "trace": [
        {"time": 0, "call": "MOV", "args": [3, 2], "line": 2}]})
    assert differences(annotated, moved) != []
