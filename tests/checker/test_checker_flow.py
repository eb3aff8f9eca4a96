"""The checker's data-flow rules: lost-line handlers, reserved variables, unreachable
code, programs without (END), busy loops, and ending while the vehicle moves. For each
code, a program that raises it (with its span) and a close one that does not."""

from __future__ import annotations

import pytest
from support.checker import apply, codes, found, one, span

# Lost-line handlers (W0301) -------------------------------------------------------------


def test_mode_3_mvi_needs_97_and_the_fix_adds_it() -> None:
    source = "(TRC 3); (MVI 1,1,50)\n(END)\n"
    diagnostic = one(source, "W0301")
    assert diagnostic.span == span(1, 10, 22)
    assert "`:97`" in diagnostic.message
    fixed = apply(source, diagnostic.fixes[0])
    assert fixed == "(TRC 3); (MVI 1,1,50)\n(END)\n:97 (MOV 0,0); (END)\n"
    assert codes(fixed) == []


@pytest.mark.parametrize(("source", "label", "where"), [
    ("(TRC 2); (MOV 3,3)\n(MOV 0,0); (END)", 98, span(1, 10, 19)),
    ("(TRC 2); (MVI 1,1,50)\n(END)", 99, span(1, 10, 22)),
    ("(TRC 3); (MOV 3,3)\n(MOV 0,0); (END)", 96, span(1, 10, 19)),
    # moving first, tracing later: the lost line may come once (TRC 3) has run
    ("(MOV 3,3); A=1; (TRC 3)\n(MOV 0,0); (END)", 96, span(1, 17, 24)),
])
def test_each_mode_and_motion_needs_its_handler(source: str, label: int, where: object) -> None:
    [diagnostic] = found(source, "W0301")
    assert f"`:{label}`" in diagnostic.message
    assert diagnostic.span == where


def test_a_variable_mode_may_be_either() -> None:
    labels = [d.message.split("`")[1] for d in found("(TRC M); (MOV 3,3)\n(MOV 0,0); (END)",
                                                      "W0301")]
    assert labels == [":96", ":98"]


@pytest.mark.parametrize("source", [
    "(TRC 3); (MVI 1,1,50)\n(END)\n:97 (END)",  # defined
    "(TRC 1); (MVI 1,1,50); (MOV 3,3)\n(MOV 0,0); (END)",  # mode 1 never jumps
    "(TRC 3); (MOV 0,0); (MVI 1,1,0)\n(END)",  # nothing moves
    "(MVI 1,1,50); (TRC 3)\n(END)",  # tracing starts after the motion
    "(TRC 3); (MVI 1,1,50)\n(END)\nA=(",  # the broken line may define :97
])
def test_no_handler_is_needed(source: str) -> None:
    assert found(source, "W0301") == []


def test_a_background_mvi_needs_97_again_and_not_96() -> None:
    # After :97, the MVI goes on in the background; another lost line goes to :97 again.
    source = "(TRC 3); (MVI 1,1,50)\n(END)\n:97 (IMG); #97\n"
    assert found(source, "W0301") == []


# Reserved variables read before they are set (W0401) -------------------------------------


def test_reading_x_before_any_img() -> None:
    diagnostic = one("(SCN 4)\nL=x; (END)", "W0401")
    assert diagnostic.span == span(2, 3, 4)
    assert "`(IMG)`" in diagnostic.message
    assert found("(SCN 4); (IMG)\nL=x; (END)", "W0401") == []


def test_left_to_right_order_within_a_statement() -> None:
    assert one("A=x+(IMG); (END)", "W0401").span == span(1, 3, 4)
    assert found("A=(IMG)+x; (END)", "W0401") == []


def test_one_path_without_the_call_is_enough() -> None:
    source = "?A>#10\n(KYO)\n:10 B=u; (END)"
    assert one(source, "W0401").span == span(3, 7, 8)
    assert found("(KYO)\n?A>#10\n:10 B=u; (END)", "W0401") == []


def test_every_kind_of_read() -> None:
    source = "(MOV s,0); ?t>#10\n:10 w++; (END)"
    assert [d.span for d in found(source, "W0401")] == [span(1, 6, 7), span(1, 13, 14),
                                                        span(2, 5, 6)]


def test_an_assignment_sets_it_too() -> None:
    assert found("z=5; A=z; (END)", "W0401") == []  # W0402 already warns about z=5


def test_a_handler_sees_what_was_set_before_the_lost_line() -> None:
    before = "(IMG); (TRC 3); (MOV 3,3)\n:10 #10\n:96 A=x; (MOV 0,0); (END)"
    after = "(TRC 3); (MOV 3,3); (IMG)\n:10 #10\n:96 A=x; (MOV 0,0); (END)"
    assert found(before, "W0401") == []
    assert one(after, "W0401").span == span(3, 7, 8)


def test_unreachable_reads_are_not_reported() -> None:
    assert found("(END); A=x", "W0401") == []


# Unreachable code (W0601, W0602) ------------------------------------------------------


def test_code_after_a_jump() -> None:
    source = ":10 A=(IMG)-180; ?A<#10\n#30\n(MOV 0,0)\nB=1\n:30 (END)"
    diagnostic = one(source, "W0601")
    assert diagnostic.span == span(3, 1, 4, end_line=4)
    assert "`#30`" in diagnostic.message


def test_label_nothing_jumps_to_after_an_end() -> None:
    diagnostic = one("(END)\n:40 A=1\n", "W0601")
    assert diagnostic.span == span(2, 5, 8)
    assert "`:40`" in diagnostic.message


def test_a_dead_loop_is_reported_once() -> None:
    assert len(found("(END)\n:10 A=1; #10\n", "W0601")) == 1


def test_code_reached_by_a_jump_or_a_lost_line_is_reachable() -> None:
    assert found("#30\n:20 A=1\n:30 ?A>#20; (END)", "W0601") == []
    assert found("(TRC 2); (MOV 3,3); (END)\n:98 (END)", "W0601") == []


@pytest.mark.parametrize("source", [
    "(MOV 0,0); (END)\n:96 (MOV 0,0); (END)\n",  # no tracing at all: defined defensively
    "(TRC 2); (MVI 3,3,10); (END)\n:98 (FRE); (END)\n:99 (FRE); (END)\n",  # no MOV: :98 idle
    "(END)\n:97 (HLD); #50\n:50 (FRE); (END)\n",  # the code a handler jumps to
])
def test_a_handler_no_lost_line_reaches_is_not_dead_code(source: str) -> None:
    assert found(source, "W0601") == []
    assert found(source, "W0205") == []


def test_code_after_a_handlers_end_is_still_dead() -> None:
    assert one("(END)\n:96 (FRE); (END); A=1\n", "W0602").span == span(2, 19, 22)
    assert one("(END)\n:96 (FRE); (END)\n:40 A=1\n", "W0601").span == span(3, 5, 8)


def test_code_after_end_on_the_same_straight_line() -> None:
    assert one("(MOV 0,0); (END); (FRE)", "W0602").span == span(1, 19, 24)
    assert one("(END)\nA=1\n", "W0602").span == span(2, 1, 4)
    assert found("(MOV 0,0); (FRE); (END)", "W0602") == []
    assert found("#10\n(END)\n:10 A=1; (END)", "W0602") == []


# No (END) (W0603) -------------------------------------------------------------------------


def test_running_off_the_end_without_any_end() -> None:
    source = "A=1\n(HLD)\n"
    diagnostic = one(source, "W0603")
    assert diagnostic.span == span(2, 1, 6)
    assert apply(source, diagnostic.fixes[0]) == "A=1\n(HLD)\n(END)\n"
    assert found("A=1\n(HLD); (END)\n", "W0603") == []


def test_a_label_at_the_very_end_marks_where_it_runs_off() -> None:
    assert one("?A>#50\nB=1\n:50\n", "W0603").span == span(3, 1, 4)


def test_a_program_that_never_ends_needs_no_end() -> None:
    assert found(":10 A=(IMG)\n#10\n", "W0603") == []
    assert found("' only a comment\n", "W0603") == []


# Busy loops (W0604) -----------------------------------------------------------------------


def test_loop_testing_a_variable_it_never_changes() -> None:
    source = "(MOV 3,3)\nA=(IMG)-180\n:10 ?A<#10\n(MOV 0,0); (END)"
    diagnostic = one(source, "W0604")
    assert diagnostic.span == span(3, 5, 11)
    assert diagnostic.related[0].span == span(3, 1, 4)
    assert "`A`" in diagnostic.message
    assert found("(MOV 3,3)\n:10 A=(IMG)-180\n?A<#10\n(MOV 0,0); (END)", "W0604") == []


def test_loop_with_no_way_out() -> None:
    diagnostic = one("B=1\n:10 C=C+1\nD=C\n#10", "W0604")
    assert diagnostic.span == span(4, 1, 4)
    assert "no way out" in diagnostic.message


@pytest.mark.parametrize("source", [
    ":10 A--; ?A>#10\n(END)",  # a counting loop ends
    ":10 (TIM 1); #10",  # waits for the device
    ":10 (ULT A); #10",  # reads a sensor
    "(TRC 3); (MOV 3,3)\n:10 #10\n:96 (MOV 0,0); (END)",  # a lost line leaves it
])
def test_loops_that_can_see_a_change(source: str) -> None:
    assert found(source, "W0604") == []


def test_blind_loop_nested_in_a_seeing_one_is_found() -> None:
    source = ":10 A=(IMG)\n:11 ?B>#11\n#10"
    diagnostic = one(source, "W0604")
    assert diagnostic.span == span(2, 5, 11)
    assert "`B`" in diagnostic.message


def test_nested_blind_loops_are_reported_once_on_the_last_backward_jump() -> None:
    source = ":10 A=1\n:11 B=2; #11\n#10"
    [diagnostic] = found(source, "W0604")
    assert diagnostic.span == span(2, 10, 13)


def test_a_misspelt_end_is_no_missing_end() -> None:
    # `(ENDD)` is E0501, with `(END)` as the guess; "no (END)" would only repeat it.
    assert codes("A=1\n(ENDD)\n") == ["E0501"]
    assert codes("A=1\n(FOO)\n") == ["E0501"]
    assert codes("A=1\n(endd)\n") == ["E0501"]  # any spelling: the blocks' effects say so
    # as an operand it cannot be the program's end (E0501 is said as well)
    assert sorted(codes("A=(ENDD)\n")) == ["E0501", "W0603"]


# Ending while moving (W0701) ------------------------------------------------------------


def test_end_while_a_mov_drives_and_the_fix_stops_first() -> None:
    source = "(MOV 3,3)\n:10 A=(IMG)-180; ?A<#10\n(END)"
    diagnostic = one(source, "W0701")
    assert diagnostic.span == span(3, 1, 6)
    fixed = apply(source, diagnostic.fixes[0])
    assert fixed.endswith("(MOV 0,0); (END)")
    assert found(fixed, "W0701") == []


def test_running_off_the_end_while_moving() -> None:
    source = "?B>#50\n(MOV 0,0); (END)\n:50 (MOV A,0)\n"
    diagnostic = one(source, "W0701")
    assert diagnostic.span == span(3, 5, 14)
    assert "run off its end" in diagnostic.message


@pytest.mark.parametrize("source", [
    "(MOV 3,3); (MOV 0,0); (END)",
    "(MOV 3,3); (HLD); (END)",
    "(MOV 3,3); (FRE); (END)",
    "(MOV 3,3); (MVI 1,1,10); (END)",
    "(MOV 0,0); (END)",
    # mode 2 stops the vehicle before jumping to :98
    "(TRC 2); (MOV 3,3)\n:10 (IMG); #10\n:98 (END)",
])
def test_ending_stopped(source: str) -> None:
    assert found(source, "W0701") == []


def test_mode_3_keeps_moving_into_the_handler() -> None:
    source = "(TRC 3); (MOV 3,3)\n:10 (IMG); #10\n:96 (END)"
    assert one(source, "W0701").span == span(3, 5, 10)


def test_an_mvi_left_in_the_background_by_mode_3_is_still_moving_at_the_end() -> None:
    source = "(TRC 3); (MVI 3,3,100)\n(END)\n:97 (END)\n"
    diagnostic = one(source, "W0701")
    assert diagnostic.span == span(3, 5, 10)
    assert "`(MVI)` that a lost line left running in the background" in diagnostic.message
    fixed = apply(source, diagnostic.fixes[0])
    assert fixed.endswith(":97 (MOV 0,0); (END)\n")
    assert found(fixed, "W0701") == []
    assert one("(TRC 3); (MVI 3,3,100)\n(END)\n:97 A=1\n", "W0701").span == span(3, 5, 8)
    # Mode 2 aborts the MVI before jumping to :99; without a handler W0301 says so.
    assert found("(TRC 2); (MVI 3,3,100)\n(END)\n:99 (END)\n", "W0701") == []
    assert codes("(TRC 3); (MVI 3,3,100)\n(END)\n") == ["W0301"]


def test_a_variable_speed_may_be_moving() -> None:
    assert one("(MOV A,0); (END)", "W0701").span == span(1, 12, 17)
