"""The checker's per-line rules, its label rules and its control-flow graph: for each
code, a program that raises it (with its span) and a close one that does not."""

from __future__ import annotations

import pytest
from support import SAMPLE
from support.checker import apply, codes, found, one, span

from rl1.compiler.analysis import analyze
from rl1.compiler.checker import build_cfg, check_line
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.parser import parse_line, parse_program
from rl1.compiler.reporting.catalogue import CODES

CHECKER_CODES = ["E0201", "E0202", "E0203", "E0204", "W0205", "W0301", "W0401", "W0402",
                 "E0501", "W0502", "E0503", "E0504", "E0505", "E0506", "E0507", "E0508",
                 "W0601", "W0602", "W0603", "W0604", "W0701"]


def test_listing_1_has_no_errors_and_only_the_missing_97() -> None:
    # (TRC 3) then (MVI 1,1,50) on line 40: a line lost during that MVI jumps to :97,
    # which Listing 1 does not define. Everything else in it is sound: reserved
    # variables are read after (IMG), every loop calls (IMG), it stops before (END).
    [diagnostic] = analyze(SAMPLE.read_text(encoding="utf-8")).diagnostics
    assert diagnostic.code == "W0301"
    assert diagnostic.span == span(40, 1, 13)
    assert "`:97`" in diagnostic.message


@pytest.mark.parametrize("code", CHECKER_CODES)
def test_every_code_is_catalogued_with_an_explanation(code: str) -> None:
    info = CODES[code]
    assert info.severity.value == ("error" if code[0] == "E" else "warning")
    explanation = info.explanation()
    assert explanation.startswith(f"# {code}: {info.title}\n")
    assert explanation.count("```") >= 4  # a failing and a fixed example


# Labels and jump targets ----------------------------------------------------------------


def test_label_of_one_digit_is_an_error_fixed_with_a_leading_zero() -> None:
    diagnostic = one(":5 A=1\n#05\n", "E0201")
    assert diagnostic.span == span(1, 1, 3)
    assert apply(":5 A=1\n#05\n", diagnostic.fixes[0]) == ":05 A=1\n#05\n"
    assert found(":05 A=1\n#05\n", "E0201") == []


def test_label_of_three_digits_or_none_has_no_fix() -> None:
    for text in (":100 A=1", ": A=1"):
        diagnostic = one(text, "E0201")
        assert diagnostic.span == span(1, 1, len(text.split()[0]) + 1)
        assert diagnostic.fixes == ()


def test_jump_target_of_one_digit_is_an_error() -> None:
    diagnostic = one(":05 A=1\n?A>#5\n", "E0202")
    assert diagnostic.span == span(2, 4, 6)
    assert diagnostic.fixes[0].edits[0].text == "#05"
    assert found(":05 A=1\n?A>#05\n", "E0202") == []


def test_jump_to_an_undefined_label() -> None:
    diagnostic = one(":10 A=1\n?A>#11\n(END)", "E0203")
    assert diagnostic.span == span(2, 4, 7)
    assert "`:10`" in (diagnostic.help or "")
    assert found(":11 A=1\n?A>#11\n(END)", "E0203") == []


def test_undefined_label_is_not_reported_while_a_line_is_broken() -> None:
    # The broken line may be the one that defines :10.
    assert found("#10\n:10 A=(\n", "E0203") == []
    assert found("#10\nA=(\n", "W0205") == []


def test_label_defined_twice_points_at_the_first() -> None:
    diagnostic = one(":10 A=1\n:10 B=2\n#10", "E0204")
    assert diagnostic.span == span(2, 1, 4)
    assert diagnostic.related[0].span == span(1, 1, 4)
    assert found(":10 A=1\n:11 B=2\n#10\n#11", "E0204") == []


def test_label_never_jumped_to_is_a_warning_with_a_fix_that_removes_it() -> None:
    source = "A=1\n:20 B=2; (END)\n"
    diagnostic = one(source, "W0205")
    assert diagnostic.span == span(2, 1, 4)
    assert apply(source, diagnostic.fixes[0]) == "A=1\nB=2; (END)\n"
    assert found("#20\n:20 B=2; (END)\n", "W0205") == []


def test_handler_labels_need_no_jump() -> None:
    assert found("(END)\n:96 (MOV 0,0)\n:97 (END)\n", "W0205") == []


# Reserved variables -----------------------------------------------------------------


@pytest.mark.parametrize(("text", "column"), [("x=1", 1), ("A=1; y++", 6)])
def test_assigning_a_reserved_variable_is_a_warning(text: str, column: int) -> None:
    diagnostic = one(text + "; (END)", "W0402")
    assert diagnostic.span == span(1, column, column + 1)
    assert "(IMG)" in diagnostic.message


def test_reading_a_reserved_variable_or_assigning_another_is_fine() -> None:
    assert found("(IMG); X=x; r=1; (END)", "W0402") == []


# Calls --------------------------------------------------------------------------------


def test_unknown_function_suggests_the_close_one() -> None:
    diagnostic = one("(MOV 0,0); (HLB); (END)", "E0501")
    assert diagnostic.span == span(1, 13, 16)
    assert apply("(MOV 0,0); (HLB); (END)", diagnostic.fixes[0]) == "(MOV 0,0); (HLD); (END)"
    assert found("(MOV 0,0); (HLD); (END)", "E0501") == []


def test_unknown_function_far_from_any_lists_them_all() -> None:
    diagnostic = one("(XYZZY)", "E0501")
    assert diagnostic.fixes == ()
    assert "KYO" in (diagnostic.help or "")


def test_lower_case_name_and_selector_are_warnings_with_fixes() -> None:
    source = "(cam p 10); (END)"
    name, selector = found(source, "W0502")
    assert (name.span, selector.span) == (span(1, 2, 5), span(1, 6, 7))
    assert apply(apply(source, selector.fixes[0]), name.fixes[0]) == "(CAM P 10); (END)"
    assert found("(CAM P 10); (END)", "W0502") == []


def test_lower_case_call_is_still_checked_as_the_built_in() -> None:
    assert "E0506" in codes("(mov 13,0); (END)")


def test_too_few_arguments_mark_the_call() -> None:
    diagnostic = one("(MVI 1,1); (END)", "E0503")
    assert diagnostic.span == span(1, 1, 10)
    assert diagnostic.message == "`(MVI l,r,cm)` takes 3 arguments, found 2"
    assert found("(MVI 1,1,50); (END)", "E0503") == []


@pytest.mark.parametrize(("text", "extra", "fixed"), [
    ("(MOV 1,2,3)", span(1, 10, 11), "(MOV 1,2)"),
    ("(FRE 1 2)", span(1, 6, 9), "(FRE)"),
    ("(CAM Z 5)", span(1, 8, 9), "(CAM Z)"),
])
def test_too_many_arguments_mark_the_extra_ones_and_remove_them(
        text: str, extra: ast.Span, fixed: str) -> None:
    diagnostic = one(text, "E0503")
    assert diagnostic.span == extra
    assert apply(text, diagnostic.fixes[0]) == fixed
    assert found(fixed, "E0503") == []


def test_arguments_are_counted_after_the_selector() -> None:
    assert one("(CAM A)", "E0503").message == (
        "`(CAM A deg)` takes 1 argument after the selector, found 0")
    assert found("(CAM A 90)", "E0503") == []


@pytest.mark.parametrize(("text", "expected"), [
    ("(CAM)", span(1, 1, 6)),  # the selector is missing: the call
    ("(ULT 1)", span(1, 6, 7)),  # a number where the letter belongs
])
def test_missing_or_numeric_selector(text: str, expected: ast.Span) -> None:
    assert one(text, "E0504").span == expected
    assert found("(ULT A); (CAM Z)", "E0504") == []


def test_selector_where_a_value_belongs() -> None:
    # The parser only makes a selector of the first argument of CAM and ULT; an AST built
    # otherwise (by a tool) is still checked.
    line, _ = parse_line("(MOV 1,2)", 1)
    (statement,) = line.statements
    assert isinstance(statement, ast.CallStmt)
    call = statement.call
    letter = ast.Selector(call.args[1].span, "B")
    odd = ast.Line(line.span, None, (ast.CallStmt(call.span, ast.Call(
        call.span, call.mnemonic, call.mnemonic_span, (call.args[0], letter))),), None)
    [diagnostic] = check_line(odd)
    assert (diagnostic.code, diagnostic.span) == ("E0504", span(1, 8, 9))


def test_unknown_selector() -> None:
    diagnostic = one("(CAM L 90)", "E0505")
    assert diagnostic.span == span(1, 6, 7)
    assert "`(CAM A deg)`" in (diagnostic.help or "")
    assert found("(CAM A 90)", "E0505") == []


@pytest.mark.parametrize(("text", "expected"), [
    ("(MOV 13,0)", span(1, 6, 8)),
    ("(TIM $FFFF)", span(1, 6, 11)),
    ("(INP $7E)", span(1, 6, 9)),
    ("(CAM P 785)", span(1, 8, 11)),
])
def test_constant_out_of_its_parameter_range(text: str, expected: ast.Span) -> None:
    assert one(text, "E0506").span == expected


def test_constants_at_the_ends_of_their_ranges_and_variables_pass() -> None:
    for text in ("(MOV -12,12)", "(TIM 1); (TIM 100)", "(INP $7D)", "(OUT 125,$FF)",
                 "(FZO $FFFF,-32768)", "(MOV A,B)", "(CAM P 784)"):
        assert found(text, "E0506") == [], text


def test_hex_value_is_shown_when_out_of_range() -> None:
    assert one("(TIM $FFFF)", "E0506").message.startswith("`$FFFF` (-1) is out of range")


def test_decimal_constant_wider_than_16_bits() -> None:
    diagnostic = one("A=40000; (END)", "E0507")
    assert diagnostic.span == span(1, 3, 8)
    assert apply("A=40000", diagnostic.fixes[0]) == "A=$9C40"
    assert one("A=B+-32769", "E0507").fixes == ()
    assert found("A=32767; B=-32768; C=$FFFF", "E0507") == []


def test_wide_constant_argument_is_reported_once() -> None:
    assert codes("(FZO 40000,0); (END)") == ["E0507"]
    assert codes("(XYZ 40000); (END)") == ["E0501", "E0507"]


@pytest.mark.parametrize("text", ["A=(MOV 1,1)", "A=B+(CAM Z)", "A=(END)"])
def test_call_without_a_result_as_an_operand(text: str) -> None:
    diagnostic = one(text, "E0508")
    start = text.index("(") + 1
    assert diagnostic.span == span(1, start, text.index(")") + 2)


def test_calls_with_a_result_are_operands() -> None:
    assert found("A=(CAM R)+(ULT B)-(KYO)+(IMG)&(INP 3)", "E0508") == []


def test_per_line_results_depend_on_the_line_alone() -> None:
    row = ast.Row(7)
    line, _ = parse_line("(mov 13,0); x=1; #5", row)
    found = check_line(line)
    row.number = 9  # the line moves, and its diagnostics with it
    assert found == check_line(parse_line("(mov 13,0); x=1; #5", 9)[0])
    assert {d.span.line for d in found} == {9}


# The control-flow graph ---------------------------------------------------------------


def test_blocks_start_at_labels_and_end_at_jumps_and_end() -> None:
    program, _ = parse_program(
        "A=1; B=2\n"  # block 0
        ":10 C=3; ?C>#20; D=4\n"  # blocks 1 (to ?C) and 2
        ":20\n"
        "(END); E=5\n"  # blocks 3 and 4 (dead), then the exit
    )
    graph = build_cfg(program)
    shapes = [[type(s).__name__ for s in block.statements] for block in graph.blocks]
    assert shapes == [["Assign", "Assign"], ["Assign", "CondJump"], ["Assign"],
                      ["CallStmt"], ["Assign"], []]
    assert [block.successors for block in graph.blocks] == [(1,), (2, 3), (3,), (), (5,), ()]
    assert graph.labels == {10: 1, 20: 3}
    assert [graph.reachable(index) for index in range(6)] == [True] * 4 + [False, False]


def test_a_label_after_the_last_statement_names_the_exit() -> None:
    graph = build_cfg(parse_program("?A>#50\n:50\n")[0])
    assert graph.labels == {50: graph.exit}
    assert graph.blocks[0].successors == (graph.exit,)


def test_a_broken_line_may_go_anywhere() -> None:
    graph = build_cfg(parse_program("#30\nA=(\n:20 B=1\n:30 C=2")[0])
    opaque = graph.blocks[1]
    assert opaque.opaque and opaque.successors == (2, 3, graph.exit)


def test_handler_edges_follow_the_tracing_mode_and_the_motion() -> None:
    program, _ = parse_program(
        "(TRC 3); A=1; (MOV 3,3)\n"  # the first event point while moving is the MOV
        ":10 (MVI 1,1,50); #10\n"
        ":96 (MOV 0,0); (END)\n"
    )
    graph = build_cfg(program)
    first, loop = graph.blocks[0], graph.blocks[1]
    assert [(e.label, e.statement, e.target) for e in first.handlers] == [(96, 2, 2)]
    assert [(e.label, e.statement, e.target) for e in loop.handlers] == [(96, 0, 2), (97, 0, None)]
