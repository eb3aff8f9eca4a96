"""The diagnostics `rl1c check` reports, held compactly (checker/compact.py: those of
single lines as their line and kind, built again when read), are those of the check on
the tree in the same order, selected as `Selection` selects a list, and every report of
them is the very text of the report of that list."""

from __future__ import annotations

from collections import Counter

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rl1.compiler.analysis import analyze, diagnose_compactly
from rl1.compiler.checker.compact import UNSET_READ, CompactDiagnostics, LineDiagnostics
from rl1.compiler.frontend.diagnostics import Severity
from rl1.compiler.reporting.render import (
    FORMATS,
    FileDiagnostics,
    Format,
    exit_status,
    report,
    summary,
)
from rl1.compiler.reporting.selection import Selection
from rl1.compiler.strategies import programs

# Lines that give diagnostics of every source: syntax errors, per-line rules, the
# program's rules, and directives that allow some of them (or nothing).
PIECES = ["A=1 B=2", "A=1; B=2", "(MOV 1,1)", "(MOV 9,9)", ":10", ":1", "#10", "#7",
          "(END)", "X=", "t=1", "A=s", "(TRC 3)", "(ENDD)", "A=99999", "",
          "' rl1: allow W0402", "A=1 B=2 ' rl1: allow E0101", "t=2 ' rl1: allow W0402",
          "' rl1: allow-file W0603", "' rl1: allow-file W0601", "' rl1: deny W0601",
          "A=A+1; ?A<#10", "\t\u00e9 A=1"]
sources = st.one_of(st.lists(st.sampled_from(PIECES), max_size=14).map("\n".join),
                    programs())
CODE_PREFIXES = st.sampled_from(["W", "W04", "W0402", "W06", "W0603", "W01"])
selections = st.builds(Selection,
                       st.none() | st.lists(CODE_PREFIXES, min_size=1).map(tuple),
                       st.none() | st.lists(CODE_PREFIXES, min_size=1).map(tuple),
                       st.none() | st.booleans())


@settings(max_examples=300, deadline=None)
@given(text=sources, selection=selections)
def test_held_diagnostics_are_the_selected_diagnostics_of_the_tree(
        text: str, selection: Selection) -> None:
    expected = selection.apply(analyze(text).diagnostics)
    held = selection.apply_compact(diagnose_compactly(text))
    assert isinstance(held, CompactDiagnostics)
    assert list(held) == expected
    assert [repr(d) for d in held] == [repr(d) for d in expected]
    assert len(held) == len(expected)
    assert Counter(held.severities()) == Counter(d.severity for d in expected)
    assert [held[index] for index in range(-len(held), len(held))] == expected + expected
    assert list(held[1::2]) == expected[1::2]
    with pytest.raises(IndexError):
        held[len(held)]


@settings(max_examples=150, deadline=None)
@given(text=sources, selection=selections, output_format=st.sampled_from(FORMATS),
       color=st.booleans())
def test_every_report_of_held_diagnostics_is_that_of_the_list(
        text: str, selection: Selection, output_format: Format, color: bool) -> None:
    compact = selection.apply_compact(diagnose_compactly(text))
    held = [FileDiagnostics("p.rob", text, compact)]
    whole = [FileDiagnostics("p.rob", text, selection.apply(analyze(text).diagnostics))]
    assert report(held, output_format, color=color) == report(whole, output_format, color=color)
    assert summary(held) == summary(whole)
    assert exit_status(held) == exit_status(whole)


def test_warnings_made_errors_are_counted_and_written_as_errors() -> None:
    text = "t=1\nt=2 ' rl1: allow W0402\nA=1 B=2\n(END)\n"
    held = Selection(warnings_as_errors=True).apply_compact(diagnose_compactly(text))
    assert [(d.code, d.severity, d.span.line) for d in held] == [
        ("W0402", Severity.ERROR, 1), ("E0101", Severity.ERROR, 3)]
    assert list(held.severities()) == [Severity.ERROR, Severity.ERROR]
    assert summary([FileDiagnostics("p.rob", text, held)]) == (
        "1 file checked: 2 errors, 0 warnings\n")


def test_merged_held_diagnostics_keep_the_order_of_their_lines_and_their_kinds() -> None:
    """The streaming check holds W0401's reads apart until the rules end, then merges
    them with the lines' own diagnostics, whose kinds they may share or not."""
    own = LineDiagnostics()
    own.add(1, 0, ("E0101", Severity.ERROR))
    own.add(3, 10, ("W0402", Severity.WARNING))
    reads = LineDiagnostics()
    reads.add(2, 5, UNSET_READ, 3)
    reads.add(3, 10, ("W0402", Severity.WARNING))
    reads.add(4, 14, UNSET_READ, 1)
    merged = own.merged(reads)
    assert list(merged.numbers) == [1, 2, 3, 3, 4]
    assert list(merged.starts) == [0, 5, 10, 10, 14]
    assert merged.columns is not None and list(merged.columns) == [0, 3, 0, 0, 1]
    assert own.columns is None  # none is held before a read is
    assert [merged.kinds[index] for index in merged.of_kind] == [
        ("E0101", Severity.ERROR), UNSET_READ, ("W0402", Severity.WARNING),
        ("W0402", Severity.WARNING), UNSET_READ]
