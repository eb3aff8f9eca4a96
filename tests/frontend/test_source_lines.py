"""Lines read without holding them all: the parser takes a source's lines one at a time
(source.iter_lines), the reporter finds the few it shows by their index
(source.LineIndex), and the first line of code past a limit on lines is found in the
text without splitting it into lines (source.first_code_line_after), as the parser
would see it, so that a limit on lines can be told before parsing."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from rl1.compiler.frontend.scanner import WHITESPACE
from rl1.compiler.frontend.source import (
    LineIndex,
    first_code_line_after,
    iter_lines,
    split_lines,
)

line_texts = st.sampled_from(["", " ", "\t", "' a comment", "  ' indented", "A=1", " (END)",
                              ":10", "x'y", "\u3000"])
line_ends = st.sampled_from(["\n", "\r\n", "\r"])


@given(st.text(alphabet="ab '\r\n\t"))
def test_the_lines_one_at_a_time_are_the_lines(text: str) -> None:
    assert list(iter_lines(text)) == split_lines(text)


@given(st.text(alphabet="ab '\r\n\t"))
def test_the_lines_found_by_index_are_the_lines(text: str) -> None:
    index = LineIndex(text)
    assert [index[number] for number in range(len(index))] == split_lines(text)


def _first_code_line_after(text: str, last: int) -> int | None:
    """The same, line by line, as the parser sees the lines."""
    return next((number for number, line in enumerate(split_lines(text), start=1)
                 if number > last and line.partition("'")[0].strip(WHITESPACE)), None)


@given(st.lists(st.tuples(line_texts, line_ends)), st.booleans(), st.integers(0, 12))
def test_the_first_line_of_code_past_a_limit_is_the_one_the_lines_have(
        lines: list[tuple[str, str]], final_end: bool, last: int) -> None:
    text = "".join(line + end for line, end in lines)
    if lines and not final_end:
        text = text.removesuffix(lines[-1][1])
    assert first_code_line_after(text, last) == _first_code_line_after(text, last)
