"""The renderers: the human layout, JSON exactly, SARIF's structure, colour, exit statuses."""

from __future__ import annotations

import io
import json
import re
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.sarif import sarif_problems

from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Edit, Fix, Related, Severity
from rl1.compiler.reporting.catalogue import CODES
from rl1.compiler.reporting.render import (
    SNIPPET_WIDTH,
    FileDiagnostics,
    artifact_uri,
    excerpt,
    exit_status,
    first_paragraph,
    report,
    use_color,
)

ERROR, WARNING, INFO = Severity.ERROR, Severity.WARNING, Severity.INFO


def one_file(text: str | None, *diagnostics: Diagnostic, name: str = "prog.rob") -> str:
    return report([FileDiagnostics(name, text, diagnostics)])


def error_at(span: Span, message: str = "something is wrong", code: str = "E0101",
             **extra: Any) -> Diagnostic:
    return Diagnostic(code, ERROR, message, span, **extra)


# The human layout ---------------------------------------------------------------------


def test_error_with_help_in_the_rustc_layout() -> None:
    diagnostic = error_at(Span(2, 5, 2, 6), "expected a variable, found the end of the line",
                          help="write an operand after `+`")
    assert one_file("(MOV 3,3)\nA=B+\n", diagnostic) == (
        "error[E0101]: expected a variable, found the end of the line\n"
        " --> prog.rob:2:5\n"
        "  |\n"
        "2 | A=B+\n"
        "  |     ^\n"
        "  |\n"
        "  = help: write an operand after `+`\n"
        "\n"
        "error: could not check `prog.rob`: 1 error emitted\n"
    )


def test_related_information_is_a_note_with_its_own_snippet_and_a_shared_gutter() -> None:
    text = "\n" * 8 + ":10 (MOV 3,3)\n:10 (FRE)\n"
    diagnostic = error_at(Span(10, 1, 10, 4), "label `:10` is defined twice", code="E0201",
                          related=(Related(Span(9, 1, 9, 4), "first defined here"),))
    assert one_file(text, diagnostic) == (
        "error[E0201]: label `:10` is defined twice\n"
        "  --> prog.rob:10:1\n"
        "   |\n"
        "10 | :10 (FRE)\n"
        "   | ^^^\n"
        "note: first defined here\n"
        "  --> prog.rob:9:1\n"
        "   |\n"
        " 9 | :10 (MOV 3,3)\n"
        "   | ^^^\n"
        "\n"
        "error: could not check `prog.rob`: 1 error emitted\n"
    )


def snippet_rows(text: str, span: Span) -> list[str]:
    """The source row and the caret row of a one-line snippet."""
    rows = one_file(text, error_at(span)).splitlines()
    return rows[3:5]


def test_tabs_expand_to_stops_of_four_in_the_line_and_under_it() -> None:
    assert snippet_rows("\tA=B+x", Span(1, 3, 1, 4)) == ["1 |     A=B+x", "  |      ^"]
    # A tab after one character takes three cells, so `=` sits at cell 4.
    assert snippet_rows("A\t=1", Span(1, 3, 1, 5)) == ["1 | A   =1", "  |     ^^"]


def test_carets_line_up_under_wide_east_asian_text() -> None:
    assert snippet_rows("全角A=1", Span(1, 3, 1, 4)) == ["1 | 全角A=1", "  |     ^"]
    # A span over wide characters is two carets per character.
    assert snippet_rows("全角A=1", Span(1, 1, 1, 3)) == ["1 | 全角A=1", "  | ^^^^"]


def test_a_span_past_the_end_of_the_line_points_after_it() -> None:
    assert snippet_rows("(MOV 3,3", Span(1, 9, 1, 10)) == ["1 | (MOV 3,3", "  |         ^"]


def test_terminal_control_characters_are_shown_not_sent() -> None:
    text = "A=\x1b[31m\x07"
    out = one_file(text, error_at(Span(1, 3, 1, 4), "unexpected character `\x1b`"))
    assert "\x1b" not in out and "\x07" not in out
    assert "1 | A=\u241b[31m\u2407" in out
    assert "unexpected character `\u241b`" in out


def test_a_multi_line_span_shows_its_first_and_last_lines() -> None:
    out = one_file("A=1\nB=2\nC=3\n", error_at(Span(1, 3, 3, 2)))
    assert out.splitlines()[3:9] == ["1 | A=1", "  |   ^", "...", "3 | C=3", "  | ^", ""]


def test_a_diagnostic_past_the_last_line_has_a_place_but_no_snippet() -> None:
    out = one_file("A=1\n", error_at(Span(5, 1, 5, 1)))
    assert out.splitlines()[:3] == ["error[E0101]: something is wrong", " --> prog.rob:5:1", ""]


def test_an_unreadable_file_is_named_without_a_place() -> None:
    unreadable = error_at(Span(1, 1, 1, 1), "gone.rob: no such file", code="E0100")
    assert one_file(None, unreadable, name="gone.rob") == (
        "error[E0100]: gone.rob: no such file\n"
        " --> gone.rob\n"
        "\n"
        "error: could not check `gone.rob`: 1 error emitted\n"
    )


def test_summary_counts_errors_and_warnings_in_rustc_words() -> None:
    def warning(line: int) -> Diagnostic:
        return Diagnostic("W0601", WARNING, "w", Span(line, 1, line, 2))

    text = "A=1\nB=2\n"
    assert one_file(text, warning(1), warning(2)).endswith(
        "\nwarning: `prog.rob`: 2 warnings emitted\n")
    mixed = one_file(text, warning(1), error_at(Span(1, 1, 1, 2)), error_at(Span(2, 1, 2, 2)))
    assert mixed.endswith("\nerror: could not check `prog.rob`: 2 errors, 1 warning emitted\n")
    advice = one_file(text, Diagnostic("W0601", INFO, "i", Span(1, 1, 1, 2)))
    assert advice.startswith("info[W0601]: i\n") and advice.endswith("  | ^\n\n")
    compile_failed = report([FileDiagnostics("p.rob", text, [error_at(Span(1, 1, 1, 2))])],
                            action="compile")
    assert compile_failed.endswith("error: could not compile `p.rob`: 1 error emitted\n")


def test_files_are_reported_in_the_order_given_and_clean_files_say_nothing() -> None:
    files = [FileDiagnostics("b.rob", "A=\n", [error_at(Span(1, 3, 1, 4))]),
             FileDiagnostics("clean.rob", "A=1\n", []),
             FileDiagnostics("a.rob", "B=\n", [error_at(Span(1, 3, 1, 4))])]
    out = report(files)
    assert "clean.rob" not in out
    assert out.index("b.rob") < out.index("a.rob")
    assert "1 error emitted\n\nerror[E0101]" in out  # a blank line between the files
    assert report([FileDiagnostics("clean.rob", "A=1\n", [])]) == ""


def test_diagnostics_are_shown_in_source_order() -> None:
    late, early = error_at(Span(2, 1, 2, 2), "late"), error_at(Span(1, 1, 1, 2), "early")
    out = one_file("A\nB\n", late, early)
    assert out.index("early") < out.index("late")


def test_colour_only_adds_escape_codes() -> None:
    diagnostic = error_at(Span(1, 3, 1, 4), related=(Related(Span(1, 1, 1, 2), "see"),),
                          help="do this")
    files = [FileDiagnostics("prog.rob", "A=%", [diagnostic])]
    plain, colored = report(files), report(files, color=True)
    assert "\x1b[" not in plain
    assert "\x1b[31m" in colored  # errors in red
    assert re.sub(r"\x1b\[[0-9;]*m", "", colored) == plain


# Excerpts: where the carets go ---------------------------------------------------------

WIDE = "あいう"
_ALPHABET = "abcdefgh" + WIDE + "\t"


def model_cell(line: str, position: int) -> int:
    """An independent model of terminal cells for the test alphabet."""
    cell = 0
    for character in line[:position]:
        cell += 4 - cell % 4 if character == "\t" else 2 if character in WIDE else 1
    return cell + max(0, position - len(line))


def model_shown(line: str) -> str:
    shown = ""
    for character in line:
        shown += " " * (4 - model_cell(shown, len(shown)) % 4) if character == "\t" else character
    return shown


@settings(max_examples=150, deadline=None)
@given(st.text(alphabet=_ALPHABET, max_size=SNIPPET_WIDTH // 2), st.data())
def test_excerpt_of_a_short_line_matches_the_cell_model(line: str, data: st.DataObject) -> None:
    first = data.draw(st.integers(0, len(line) + 2))
    last = data.draw(st.integers(first, len(line) + 3))
    shown, caret, width = excerpt(line, first, last)
    assert shown == model_shown(line)
    assert caret == model_cell(line, first)
    assert width == max(1, model_cell(line, last) - caret)


def glyph_at(shown: str, cell: int) -> str | None:
    at = 0
    for character in shown:
        if at == cell:
            return character
        at += 2 if character in WIDE else 1
    return None


@settings(max_examples=100, deadline=None)
@given(st.text(alphabet=_ALPHABET, min_size=SNIPPET_WIDTH + 1, max_size=4 * SNIPPET_WIDTH),
       st.data())
def test_a_long_line_is_cut_to_a_window_that_holds_the_span(
    line: str, data: st.DataObject
) -> None:
    first = data.draw(st.integers(0, len(line) - 1))
    last = data.draw(st.integers(first, len(line)))
    shown, caret, width = excerpt(line, first, last)
    assert model_cell(shown, len(shown)) <= SNIPPET_WIDTH + 2 * len("...") + 3
    expected = " " if line[first] == "\t" else line[first]
    assert glyph_at(shown, caret) == expected
    assert caret + width <= model_cell(shown, len(shown))


def test_a_megabyte_line_is_shown_around_the_span() -> None:
    line = "A=" + "1+" * 500_000 + "%"
    out = one_file(line, error_at(Span(1, len(line), 1, len(line) + 1)))
    assert max(len(row) for row in out.splitlines()) < 2 * SNIPPET_WIDTH
    source_row, caret_row = out.splitlines()[3:5]
    assert source_row.startswith("1 | ...1+1+") and source_row.endswith("+%")
    assert caret_row.index("^") == source_row.index("%")


def test_a_huge_message_is_cut_for_people_but_not_for_machines() -> None:
    word = "A" * 100_000
    diagnostic = error_at(Span(1, 1, 1, 100_001), f"`{word}` is not a variable")
    assert len(one_file(word, diagnostic).splitlines()[0]) < 500
    files = [FileDiagnostics("p.rob", word, [diagnostic])]
    assert json.loads(report(files, "json"))[0]["message"] == diagnostic.message


# JSON ---------------------------------------------------------------------------------


def test_json_has_every_key_with_one_based_exclusive_spans() -> None:
    fix = Fix("close the call", (Edit(Span(1, 9, 1, 9), ")"),), safe=True)
    files = [
        FileDiagnostics("a.rob", "(MOV 3,3\n", [
            error_at(Span(1, 9, 1, 10), "expected `)`", help="close the call with `)`",
                     fixes=(fix,)),
        ]),
        FileDiagnostics("b.rob", ":10\n:10\n", [
            Diagnostic("W0201", WARNING, "twice", Span(2, 1, 2, 4),
                       related=(Related(Span(1, 1, 1, 4), "first defined here"),)),
        ]),
    ]
    assert json.loads(report(files, "json")) == [
        {"file": "a.rob", "line": 1, "column": 9, "end_line": 1, "end_column": 10,
         "severity": "error", "code": "E0101", "message": "expected `)`",
         "help": "close the call with `)`",
         "fixes": [{"title": "close the call", "applicability": "safe", "edits": [
             {"line": 1, "column": 9, "end_line": 1, "end_column": 9, "text": ")"}]}],
         "related": []},
        {"file": "b.rob", "line": 2, "column": 1, "end_line": 2, "end_column": 4,
         "severity": "warning", "code": "W0201", "message": "twice", "help": None,
         "fixes": [],
         "related": [{"line": 1, "column": 1, "end_line": 1, "end_column": 4,
                      "message": "first defined here"}]},
    ]


def test_json_is_ascii_and_an_empty_array_when_all_is_well() -> None:
    files = [FileDiagnostics("プログラム.rob", "A=％", [error_at(Span(1, 3, 1, 4), "`％`")])]
    out = report(files, "json")
    assert out.isascii()
    assert json.loads(out)[0]["file"] == "プログラム.rob"
    assert json.loads(report([FileDiagnostics("p.rob", "", [])], "json")) == []


# SARIF --------------------------------------------------------------------------------


def sarif(files: list[FileDiagnostics]) -> dict[str, Any]:
    log: dict[str, Any] = json.loads(report(files, "sarif"))
    assert sarif_problems(log) == []
    return log


def test_sarif_describes_every_rule_of_the_catalogue() -> None:
    (run,) = sarif([])["runs"]
    assert run["columnKind"] == "unicodeCodePoints"
    driver = run["tool"]["driver"]
    assert driver["name"] == "rl1c"
    assert [rule["id"] for rule in driver["rules"]] == list(CODES)
    for rule in driver["rules"]:
        info = CODES[rule["id"]]
        assert rule["shortDescription"]["text"] == info.title
        assert rule["fullDescription"]["text"] == first_paragraph(info.explanation())
        assert rule["fullDescription"]["text"]
    e0100 = driver["rules"][list(CODES).index("E0100")]
    assert e0100["defaultConfiguration"] == {"level": "error"}
    assert run["results"] == []


def test_sarif_result_with_region_and_fix() -> None:
    fix = Fix("close the call", (Edit(Span(1, 9, 1, 9), ")"),))
    diagnostic = error_at(Span(1, 9, 1, 10), "expected `)`", help="close the call with `)`",
                          fixes=(fix,))
    (run,) = sarif([FileDiagnostics("dir/my prog.rob", "(MOV 3,3\n", [diagnostic])])["runs"]
    location = {"uri": "dir/my%20prog.rob"}
    assert run["results"] == [{
        "ruleId": "E0101",
        "ruleIndex": list(CODES).index("E0101"),
        "level": "error",
        "message": {"text": "expected `)`\nhelp: close the call with `)`"},
        "locations": [{"physicalLocation": {
            "artifactLocation": location,
            "region": {"startLine": 1, "startColumn": 9, "endLine": 1, "endColumn": 10}}}],
        "fixes": [{"description": {"text": "close the call"}, "artifactChanges": [{
            "artifactLocation": location,
            "replacements": [{
                "deletedRegion": {"startLine": 1, "startColumn": 9, "endLine": 1,
                                  "endColumn": 9},
                "insertedContent": {"text": ")"}}]}]}],
    }]


def test_sarif_levels_related_locations_and_unreadable_files() -> None:
    files = [
        FileDiagnostics("a.rob", ":10\n:10\n", [
            Diagnostic("W0201", WARNING, "twice", Span(2, 1, 2, 4),
                       related=(Related(Span(1, 1, 1, 4), "first defined here"),)),
            Diagnostic("I0001", INFO, "advice", Span(1, 1, 1, 2)),
        ]),
        FileDiagnostics("gone.rob", None, [error_at(Span(1, 1, 1, 1), "gone", code="E0100")]),
    ]
    advice, warning, unreadable = sarif(files)["runs"][0]["results"]  # in source order
    assert (warning["level"], advice["level"], unreadable["level"]) == ("warning", "note", "error")
    assert "ruleIndex" not in advice  # a code the catalogue does not know has no rule
    assert warning["relatedLocations"][0]["message"] == {"text": "first defined here"}
    assert unreadable["locations"] == [
        {"physicalLocation": {"artifactLocation": {"uri": "gone.rob"}}}]


def test_artifact_uris_are_relative_as_given_or_file_uris() -> None:
    assert artifact_uri("examples/sample.rob") == "examples/sample.rob"
    assert artifact_uri("my prog.rob") == "my%20prog.rob"
    assert artifact_uri("<stdin>") == "%3Cstdin%3E"
    assert artifact_uri("/tmp/a b.rob") == "file:///tmp/a%20b.rob"
    assert artifact_uri("ロボ.rob") == "%E3%83%AD%E3%83%9C.rob"


@pytest.mark.parametrize("break_it, problem", [
    (lambda log: log.pop("version"), "missing 'version'"),
    (lambda log: log["runs"][0]["results"][0].update(level="fatal"), "not one of"),
    (lambda log: log["runs"][0]["results"][0].update(ruleIndex=0), "does not name rule"),
    (lambda log: log["runs"][0].update(colour="red"), "'colour' is not a property"),
    (lambda log: log["runs"][0]["results"][0]["locations"][0]["physicalLocation"]["region"]
     .update(endLine=0), "0 < 1"),
    (lambda log: log["runs"][0]["results"][0]["locations"][0]["physicalLocation"]
     ["artifactLocation"].update(uri="a b"), "not a URI reference"),
])
def test_the_sarif_checker_finds_broken_logs(break_it: Any, problem: str) -> None:
    files = [FileDiagnostics("a.rob", "A=\n", [error_at(Span(1, 3, 1, 4), code="E0102")])]
    log = json.loads(report(files, "sarif"))
    break_it(log)
    assert any(problem in found for found in sarif_problems(log))


def test_first_paragraph_skips_headings_and_joins_lines() -> None:
    assert first_paragraph("# T\n\nFirst line\nsecond.\n\nOther.\n") == "First line second."


# Exit status and colour choice --------------------------------------------------------


def test_exit_status_unreadable_beats_errors_beats_warnings() -> None:
    warning = Diagnostic("W0601", WARNING, "w", Span(1, 1, 1, 2))
    unreadable = FileDiagnostics("gone.rob", None, [error_at(Span(1, 1, 1, 1), code="E0100")])
    assert exit_status([]) == 0
    assert exit_status([FileDiagnostics("p.rob", "A", [warning])]) == 0
    with_error = FileDiagnostics("p.rob", "A", [warning, error_at(Span(1, 1, 1, 2))])
    assert exit_status([with_error]) == 1
    assert exit_status([with_error, unreadable]) == 2


class _Stream(io.StringIO):
    def __init__(self, tty: bool) -> None:
        super().__init__()
        self.tty = tty

    def isatty(self) -> bool:
        return self.tty


def test_colour_auto_means_a_terminal_without_no_color(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("NO_COLOR", raising=False)
    monkeypatch.setenv("TERM", "dumb")  # an editor's pane, which shows escapes as text
    assert not use_color("auto", _Stream(tty=True))
    assert use_color("always", _Stream(tty=True))
    monkeypatch.setenv("TERM", "xterm-256color")
    assert use_color("auto", _Stream(tty=True))
    assert not use_color("auto", _Stream(tty=False))
    assert use_color("always", _Stream(tty=False))
    assert not use_color("never", _Stream(tty=True))
    monkeypatch.setenv("NO_COLOR", "1")
    assert not use_color("auto", _Stream(tty=True))
    assert use_color("always", _Stream(tty=True))


def test_combining_marks_take_no_cell_and_a_trailing_wide_space_stays_visible() -> None:
    assert snippet_rows("e\u0301A=1", Span(1, 3, 1, 4)) == ["1 | e\u0301A=1", "  |  ^"]
    assert snippet_rows("(MOV\u3000", Span(1, 5, 1, 6)) == ["1 | (MOV\u3000", "  |     ^^"]


def test_concise_is_one_line_per_diagnostic_with_control_characters_shown() -> None:
    files = [FileDiagnostics("a.rob", "A\nB\n", [error_at(Span(2, 1, 2, 2), "late"),
                                                error_at(Span(1, 3, 1, 4), "bell\x07")])]
    assert report(files, "concise") == ("a.rob:1:3: error[E0101]: bell\u2407\n"
                                        "a.rob:2:1: error[E0101]: late\n")
    assert report([FileDiagnostics("a.rob", "A\n", [])], "concise") == ""
