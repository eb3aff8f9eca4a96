"""Suppression comments (spec/language.md, section 2.5): `' rl1: allow CODE` on a line,
`' rl1: allow-file CODE` in a file, errors never allowed, and W0107 for a directive that
allows nothing."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support.checker import codes, found, span

from rl1.compiler.analysis import analyze
from rl1.compiler.frontend.source import split_lines
from rl1.compiler.strategies import programs

# W0301 on line 1 (no :97 for the MVI in mode 3); W0602 on line 3 (after the END).
WARNED = "(TRC 3); (MVI 3,3,100)\n(END)\nA=1\n"


def with_comment(line: int, comment: str, text: str = WARNED) -> str:
    lines = text.split("\n")
    lines[line - 1] += " '" + comment
    return "\n".join(lines)


def test_the_program_has_the_two_warnings_to_allow() -> None:
    assert codes(WARNED) == ["W0301", "W0602"]


@pytest.mark.parametrize("comment, left", [
    ("rl1: allow W0301", ["W0602"]),
    ("rl1:allow W0301", ["W0602"]),
    (" rl1: allow w0301 the MVI cannot lose the line", ["W0602"]),
    # W0602 is on line 3, not here: allowing it on line 1 allows nothing.
    ("reviewed rl1: allow W0301, W0602", ["W0107", "W0602"]),
])
def test_allow_silences_a_warning_on_its_own_line_only(comment: str, left: list[str]) -> None:
    assert codes(with_comment(1, comment)) == left
    # On another line, the same comment silences nothing there and is reported.
    elsewhere = codes(with_comment(2, comment))
    assert "W0301" in elsewhere and "W0107" in elsewhere


@pytest.mark.parametrize("line", [1, 2, 4])
def test_allow_file_silences_a_warning_anywhere(line: int) -> None:
    text = with_comment(line, "rl1: allow-file W0301, W0602") if line < 4 else \
        WARNED + "' rl1: allow-file W0301, W0602\n"
    assert codes(text) == []


def place(text: str, marked: str) -> tuple[int, int]:
    """The columns of `marked` in the one-line `text`, as a span counts them."""
    column = text.index(marked) + 1
    return column, column + len(marked)


def test_errors_cannot_be_allowed() -> None:
    text = "#50 ' rl1: allow E0203 E0101\n"
    assert codes(text) == ["E0203", "W0107", "W0107"]
    problems = found(text, "W0107")
    assert [d.span for d in problems] == [span(1, *place(text, "E0203")),
                                          span(1, *place(text, "E0101"))]
    assert all("errors cannot be allowed" in d.message for d in problems)


@pytest.mark.parametrize("comment, says, marked", [
    ("rl1: allow", "names no code", "rl1: allow"),
    ("rl1: allow-file", "names no code", "rl1: allow-file"),
    ("rl1: alow W0602", "`rl1: alow` is not a directive", "rl1: alow"),
    ("rl1: allow W0999", "no W0999 is reported on this line", "W0999"),
    ("rl1: allow-file W0603", "no W0603 is reported in this file", "W0603"),
    ("rl1: allow X12", "`X12` is not a diagnostic code", "X12"),
])
def test_a_directive_that_allows_nothing_is_w0107(comment: str, says: str,
                                                  marked: str) -> None:
    text = "(END) '" + comment + "\n"
    (problem,) = found(text, "W0107")
    assert says in problem.message
    assert problem.span == span(1, *place(text, marked))


def test_rl1_must_start_a_word_and_other_comments_are_not_directives() -> None:
    assert codes("(END) ' xrl1: allow W0602\nA=1\n") == ["W0602"]
    assert codes("(END) ' allow W0602\nA=1\n") == ["W0602"]


@given(programs())
def test_a_program_without_directives_keeps_every_diagnostic(text: str) -> None:
    # The strategies' comments never hold `rl1:`; suppression must then change nothing.
    from rl1.compiler.checker import check
    from rl1.compiler.frontend.parser import parse_program

    program, diagnostics = parse_program(text)
    diagnostics.extend(check(program))
    assert sorted(map(repr, analyze(text).diagnostics)) == sorted(map(repr, diagnostics))


@given(programs(), st.data())
def test_allowing_every_warning_on_its_line_leaves_only_errors(text: str,
                                                               data: st.DataObject) -> None:
    lines = split_lines(text)
    warnings: dict[int, set[str]] = {}
    for diagnostic in analyze(text).diagnostics:
        if not diagnostic.is_error and diagnostic.span.line <= len(lines):
            warnings.setdefault(diagnostic.span.line, set()).add(diagnostic.code)
    for line, line_codes in warnings.items():
        quote = "" if "'" in lines[line - 1] else " '"
        lines[line - 1] += f"{quote} rl1: allow {', '.join(sorted(line_codes))}"
    allowed = analyze("\n".join(lines) + "\n").diagnostics
    kept = [d for d in allowed if not d.is_error and d.span.line in warnings]
    assert kept == [], [(d.code, d.span.line, d.message) for d in kept]
