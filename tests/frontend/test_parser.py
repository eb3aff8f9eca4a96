"""The parser: spans, left-to-right expressions, selectors and syntax errors."""


import pytest
from support import SAMPLE

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic
from rl1.compiler.frontend.parser import parse_line, parse_program


def test_sample_parses_without_syntax_errors() -> None:
    program, diagnostics = parse_program(SAMPLE.read_text(encoding="utf-8"))
    assert diagnostics == []
    assert len(program.lines) == 43
    labels = [line.label.number for line in program.lines if line.label]
    assert labels == [10, 12, 13, 14, 20, 21, 22, 29, 40, 96, 99]


def test_expression_keeps_operators_in_order_with_spans() -> None:
    line, diagnostics = parse_line("C=a<3+b>6+C", 4)
    assert diagnostics == []
    (assign,) = line.statements
    assert isinstance(assign, ast.Assign)
    assert [step.op for step in assign.rest] == ["<", "+", ">", "+"]
    assert assign.span == ast.Span(4, 1, 4, 12)
    assert assign.rest[1].op_span == ast.Span(4, 6, 4, 7)


def test_minus_after_operand_is_an_operator_and_before_digits_a_sign() -> None:
    line, _ = parse_line("A=B--5; d=-450", 1)
    first, second = line.statements
    assert isinstance(first, ast.Assign) and isinstance(second, ast.Assign)
    assert first.rest[0].op == "-"
    assert isinstance(first.rest[0].operand, ast.Const)
    assert first.rest[0].operand.value == -5
    assert isinstance(second.first, ast.Const) and second.first.value == -450


def test_camera_and_ultrasonic_selectors_are_letters_not_variables() -> None:
    line, _ = parse_line("(CAM P c); (ULT A)", 1)
    cam, ult = (statement.call for statement in line.statements
                if isinstance(statement, ast.CallStmt))
    assert cam.args == (ast.Selector(ast.Span(1, 6, 1, 7), "P"), ast.Var(ast.Span(1, 8, 1, 9), "c"))
    assert isinstance(ult.args[0], ast.Selector)


def test_hex_is_a_bit_pattern() -> None:
    line, _ = parse_line("A=$FFFF", 1)
    (assign,) = line.statements
    assert isinstance(assign, ast.Assign) and isinstance(assign.first, ast.Const)
    assert assign.first.value == -1


def test_error_on_one_line_does_not_hide_the_next() -> None:
    _, diagnostics = parse_program("A=\nB=(MOV 1\nC=1\n")
    assert [(d.code, d.span.line) for d in diagnostics] == [("E0101", 1), ("E0101", 2)]


def test_multi_letter_word_and_bare_mnemonic_get_specific_messages() -> None:
    _, [word] = parse_line("AB=3", 1)
    _, [bare] = parse_line("MOV 3,3", 1)
    assert word.code == bare.code == "E0103"
    assert "one letter" in word.message
    assert bare.help == "write `(MOV ...)`"


def test_messages_quote_an_excerpt_of_a_huge_token_but_span_all_of_it() -> None:
    word = "AB" * 9_000
    _, [diagnostic] = parse_line(word + "=1", 1)
    assert diagnostic.code == "E0103"
    assert len(diagnostic.message) < 100
    assert diagnostic.span.end_column == len(word) + 1


def test_hex_constant_takes_hex_digits_only() -> None:
    for text in ("$0x10", "$", "$10000", "$0FG"):
        _, diagnostics = parse_line(f"A={text}", 1)
        assert [d.code for d in diagnostics] == ["E0105"], text
    _, diagnostics = parse_line("A=$00FF", 1)
    assert diagnostics == []


def test_a_line_of_full_width_spaces_is_an_error_not_blank() -> None:
    _, [diagnostic] = parse_line("\u3000\u3000", 1)
    assert diagnostic.code == "E0102"
    assert diagnostic.help is not None and "full-width space" in diagnostic.help


def test_a_line_with_a_syntax_error_keeps_its_label() -> None:
    program, [diagnostic] = parse_program("#10\n:10 A=(MOV 1\n(END)\n")
    broken = program.lines[1]
    assert diagnostic.code == "E0101" and not broken.ok
    assert broken.label == ast.LabelDef(ast.Span(2, 1, 2, 4), ":10", 10)
    assert broken.statements == ()


def test_a_line_of_more_code_than_is_read_is_e0106_and_nothing_else() -> None:
    line, [diagnostic] = parse_line("A=1;" * 5_000 + "B", 7)
    assert (diagnostic.code, diagnostic.span.line) == ("E0106", 7)
    assert "20,001 characters" in diagnostic.message
    assert line.statements == () and not line.ok
    long_comment, diagnostics = parse_line("A=1 '" + "x" * 100_000, 1)
    assert diagnostics == [] and len(long_comment.statements) == 1


def only(text: str) -> Diagnostic:
    _, [diagnostic] = parse_line(text, 1)
    return diagnostic


def edited(text: str, diagnostic: Diagnostic) -> str:
    """`text`, one line, with the edits of the diagnostic's only fix made."""
    (fix,) = diagnostic.fixes
    for edit in sorted(fix.edits, key=lambda e: e.span.column, reverse=True):
        text = text[:edit.span.column - 1] + edit.text + text[edit.span.end_column - 1:]
    return text


@pytest.mark.parametrize("text", ["A = B * 2", "A=B/2", "A=B%4"])
def test_multiplying_and_dividing_are_said_to_be_shifts(text: str) -> None:
    diagnostic = only(text)
    assert diagnostic.code == "E0102"
    assert "RL/I has no `*`, `/` or `%`" in (diagnostic.help or "")
    assert "ASCII" not in (diagnostic.help or "")


@pytest.mark.parametrize("text, says", [
    ("A=B!", "`!` has no meaning in RL/I code"),
    ("A=\x01", "a control character"),
    ("A=B＋1", "type the ASCII `+`"),
    ("A=B→1", "RL/I code is ASCII"),
])
def test_other_characters_get_help_that_fits_them(text: str, says: str) -> None:
    assert says in (only(text).help or "")


@pytest.mark.parametrize("text, fixed", [
    ("(MOV 3 -3)", "(MOV 3,-3)"),
    ("(MOV A  -12)", "(MOV A,-12)"),
    ("(CAM A -5)", "(CAM A,-5)"),
])
def test_a_negative_argument_after_a_space_needs_a_comma(text: str, fixed: str) -> None:
    diagnostic = only(text)
    assert diagnostic.code == "E0101"
    assert "separate a negative argument with a comma" in (diagnostic.help or "")
    assert "unary minus" not in (diagnostic.help or "")
    assert edited(text, diagnostic) == fixed
    assert parse_line(fixed, 1)[1] == []


def test_a_spaced_minus_in_a_call_gets_the_comma_help_but_no_fix() -> None:
    diagnostic = only("(MOV 3 - 3)")
    assert "comma" in (diagnostic.help or "") and diagnostic.fixes == ()
    assert "unary minus" in (only("A=-B").help or "")


@pytest.mark.parametrize("text, fixed", [
    ("A=1 B=2", "A=1; B=2"),
    ("A=1 (MOV 3,3)", "A=1; (MOV 3,3)"),
    ("(MOV 3,3) #10", "(MOV 3,3); #10"),
    ("A=B+1 ?A=#10", "A=B+1; ?A=#10"),
])
def test_two_statements_without_a_semicolon_get_one(text: str, fixed: str) -> None:
    diagnostic = only(text)
    assert "statements on one line are separated by `;`" in (diagnostic.help or "")
    assert edited(text, diagnostic) == fixed
    assert parse_line(fixed, 1)[1] == []


@pytest.mark.parametrize("text, fixed", [("GOTO 10", "#10"), ("goto 5", "#05"),
                                         ("A=1; JMP 99", "A=1; #99")])
def test_goto_is_said_to_be_a_hash_jump(text: str, fixed: str) -> None:
    diagnostic = only(text)
    assert diagnostic.code == "E0103"
    assert "RL/I jumps with `#` and two digits" in (diagnostic.help or "")
    assert edited(text, diagnostic) == fixed


def test_goto_without_a_label_number_gets_the_help_without_a_fix() -> None:
    for text in ("GOTO A", "GOTO 100", "GOTO"):
        diagnostic = only(text)
        assert "`#10`" in (diagnostic.help or "") and diagnostic.fixes == ()


def test_if_is_said_to_be_a_conditional_jump() -> None:
    assert "`?A=#10` jumps to `:10` when A is 0" in (only("IF A=0 GOTO 10").help or "")
