"""`analysis.fix`, what `rl1c check --fix` runs: the checker's automatic fixes made round
after round until none is left, keeping the text's line ends, never a guess."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from rl1.compiler.analysis import analyze, fix
from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Edit, Fix
from rl1.compiler.frontend.edits import apply_edits, compatible
from rl1.compiler.frontend.source import LINE_BREAK
from rl1.compiler.strategies import programs


def fixable(diagnostic: Diagnostic) -> bool:
    return any(one.automatic for one in diagnostic.fixes)


@settings(deadline=None)
@given(programs())
def test_after_fix_no_diagnostic_with_an_automatic_fix_is_left(text: str) -> None:
    fixed = fix(text)
    assert [d.code for d in fixed.analysis.diagnostics if fixable(d)] == []
    assert fixed.analysis.diagnostics == analyze(fixed.text).diagnostics
    assert (fixed.fixes == 0) == (fixed.text == text)


@settings(deadline=None)
@given(programs())
def test_fix_keeps_the_line_ends_and_changes_nothing_a_second_time(text: str) -> None:
    fixed = fix(text)
    before = set(LINE_BREAK.findall(text)) or {"\n"}
    assert set(LINE_BREAK.findall(fixed.text)) <= before
    again = fix(fixed.text)
    assert (again.text, again.fixes) == (fixed.text, 0)


@given(programs(), st.sampled_from(["W", "E", "W06", "E05"]))
def test_fix_makes_only_the_fixes_of_what_it_keeps(text: str, prefix: str) -> None:
    fixed = fix(text, keep=lambda d: d.code.startswith(prefix))
    left = [d for d in fixed.analysis.diagnostics if fixable(d) and d.code.startswith(prefix)]
    assert left == []
    if not any(fixable(d) and d.code.startswith(prefix) for d in analyze(text).diagnostics):
        assert fixed.text == text


def test_a_guess_at_a_misspelt_name_is_not_made() -> None:
    text = "A=1; (TIN 5)\n(END)\n"
    (guess,) = [d for d in analyze(text).diagnostics if d.code == "E0501"]
    assert guess.fixes and not any(one.automatic for one in guess.fixes)
    assert fix(text).text == text


def test_fixes_that_meet_at_one_place_wait_for_the_next_round() -> None:
    # No (END) and still moving at the end: both fixes add a line there. The (END) comes
    # first; the next round stops the vehicle before it.
    fixed = fix("(MOV 3,3)\r\n")
    assert fixed.text == "(MOV 3,3)\r\n(MOV 0,0); (END)\r\n"
    assert fixed.fixes == 2


def test_apply_edits_writes_line_breaks_as_the_text_ends_its_lines() -> None:
    text = "A=1\r\nB=2"
    edits = [Edit(Span(2, 4, 2, 4), "\nC=3"), Edit(Span(1, 1, 1, 2), "Z")]
    assert apply_edits(text, edits) == "Z=1\r\nB=2\r\nC=3"
    assert apply_edits("A=1", [Edit(Span(1, 99, 1, 99), "\n(END)")]) == "A=1\n(END)"


def test_compatible_drops_a_fix_that_overlaps_or_meets_one_kept_before() -> None:
    first = Fix("a", (Edit(Span(1, 1, 1, 4), "x"),))
    overlapping = Fix("b", (Edit(Span(1, 3, 1, 6), "y"),))
    same_place = Fix("c", (Edit(Span(1, 1, 1, 1), "z"),))
    after = Fix("d", (Edit(Span(1, 4, 1, 5), "w"),))
    assert compatible([first, overlapping, same_place, after]) == [first, after]
