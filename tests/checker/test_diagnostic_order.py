"""`sort_by_place` (what `diagnose` and the reports sort with, without a key tuple a
diagnostic) gives exactly the order of a sort by `sort_key`, equal keys included."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity, sort_by_place, sort_key

diagnostics = st.builds(
    lambda code, line, column, message: Diagnostic(
        code, Severity.ERROR, message, ast.Span(line, column, line, column + 1)),
    st.sampled_from(["E0101", "E0203", "W0601", "W0603", "I0001"]),
    st.integers(1, 4), st.integers(1, 4), st.sampled_from(["a", "b", "c"]))


@given(st.lists(diagnostics, max_size=30))
def test_sorting_by_place_is_sorting_by_the_key(found: list[Diagnostic]) -> None:
    expected = sorted(found, key=sort_key)
    sort_by_place(found)
    assert [id(d) for d in found] == [id(d) for d in expected]
