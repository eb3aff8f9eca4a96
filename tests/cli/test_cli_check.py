"""`rl1c check` and `rl1c explain`: formats, exit statuses, and bad input of every kind.

Whatever the input, `rl1c check` ends with 0, 1 or 2 and a well-formed report, never a
traceback; an unexpected failure inside rl1c ends with 3 and a short message.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT, TEST_DATA
from support.cli import Result, rl1c
from support.sarif import sarif_problems

from rl1.compiler import analysis
from rl1.compiler.checker.compact import CompactDiagnostics, LineDiagnostics
from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity
from rl1.compiler.reporting.catalogue import CODES

SAMPLE = ROOT / "examples" / "sample.rob"
CP932_COMMENTS = TEST_DATA / "cp932_comments.rob"


def run(*args: str, stdin: bytes = b"") -> Result:
    return rl1c(*args, stdin=stdin)


def check_json(*args: str, stdin: bytes = b"") -> tuple[int, list[dict[str, Any]]]:
    result = run("check", "--format", "json", *args, stdin=stdin)
    return result.exit_code, json.loads(result.stdout)


def write(tmp_path: Path, data: bytes | str, name: str = "prog.rob") -> str:
    path = tmp_path / name
    if isinstance(data, str):
        path.write_text(data, encoding="utf-8", newline="")
    else:
        path.write_bytes(data)
    return str(path)


# Exit statuses and formats ------------------------------------------------------------


def test_the_sample_program_has_no_errors() -> None:
    result = run("check", str(SAMPLE))
    assert result.exit_code == 0, result.stdout
    assert "error" not in result.stdout.replace("0 errors", "")
    assert result.stdout.endswith("\n1 file checked: 0 errors, 1 warning\n")


def test_errors_exit_1_with_the_place_and_the_line(tmp_path: Path) -> None:
    name = write(tmp_path, "(MOV 3,3)\nA=B+\n")
    result = run("check", name)
    assert result.exit_code == 1
    assert result.stdout.startswith("error[E0101]: ")
    assert f" --> {name}:2:5\n  |\n2 | A=B+\n  |     ^\n" in result.stdout
    # One summary, of the whole check (issue 22: a line per file came before it).
    assert result.stdout.endswith("  |     ^\n\n1 file checked: 1 error, 0 warnings\n")
    assert "could not check" not in result.stdout


def test_compiled_code_given_as_a_source_is_named_so(tmp_path: Path) -> None:
    # Issue 22: an .ilc file renamed .rob was "a binary file".
    compiled = tmp_path / "p.ilc"
    assert run(write(tmp_path, "A=1\n(END)\n"), "-o", str(compiled)).exit_code == 0
    renamed = write(tmp_path, compiled.read_bytes(), "renamed.rob")
    for args, stdin, name in ((("check", renamed), b"", renamed),
                              (("check", "-"), compiled.read_bytes(), "<stdin>"),
                              (("fmt", str(compiled)), b"", str(compiled)),
                              ((str(compiled),), b"", str(compiled))):  # compile
        result = run(*args, stdin=stdin)
        assert result.exit_code == 2
        assert f"cannot read the source file `{name}`: it is compiled code (an .ilc file), " \
               "not RL/I source\n" in result.output
        assert "binary" not in result.output
        assert "run it with `rl1c run`, under a name that ends in .ilc, or show it as text " \
               "with `rl1c dis`" in result.output
        assert "could not check" not in result.output
        assert "could not format" not in result.output  # fmt has its own summary line


def test_a_file_that_cannot_be_read_is_not_counted_as_checked(tmp_path: Path) -> None:
    missing = str(tmp_path / "nosuch.rob")
    alone = run("check", missing)
    assert alone.exit_code == 2
    assert alone.stdout.startswith(f"error[E0100]: cannot read the source file `{missing}`")
    assert alone.stdout.endswith("\n\nno file checked: 1 file could not be read\n")
    name = write(tmp_path, "(MOV 3,3)\nA=B+\n")
    both = run("check", missing, name)
    assert both.exit_code == 2
    assert both.stdout.endswith("\n1 file checked: 1 error, 0 warnings; 1 file could not "
                                "be read\n")


def test_warnings_alone_exit_0(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def only_a_warning(text: str) -> CompactDiagnostics:
        warning = Diagnostic("W0601", Severity.WARNING, "odd", Span(1, 1, 1, 2))
        return CompactDiagnostics(text, LineDiagnostics(), lambda *_: True, [warning])

    monkeypatch.setattr(analysis, "diagnose_compactly", only_a_warning)
    result = run("check", write(tmp_path, "A=1\n"))
    assert result.exit_code == 0
    assert "warning[W0601]: odd" in result.stdout


def test_json_reports_every_file_in_one_array_in_order(tmp_path: Path) -> None:
    first = write(tmp_path, "A=\n", "first.rob")
    second = write(tmp_path, "B=1\nC=%\n", "second.rob")
    status, items = check_json(second, first)
    assert status == 1
    assert [(i["file"], i["line"], i["column"], i["code"]) for i in items] == [
        (second, 2, 3, "E0102"), (first, 1, 3, "E0101")]


def test_sarif_output_is_well_formed(tmp_path: Path) -> None:
    result = run("check", "--format", "sarif", write(tmp_path, "A=％\n"), "missing.rob")
    assert result.exit_code == 2
    log = json.loads(result.stdout)
    assert sarif_problems(log) == []
    assert [r["ruleId"] for r in log["runs"][0]["results"]] == ["E0102", "E0100"]


def test_standard_input_is_read_for_a_dash() -> None:
    status, items = check_json("-", stdin=b"A=\n")
    assert status == 1
    assert items[0]["file"] == "<stdin>"


def test_colour_is_off_when_not_a_terminal_unless_asked(tmp_path: Path) -> None:
    name = write(tmp_path, "A=\n")
    assert "\x1b[" not in run("check", name).stdout
    assert "\x1b[" not in run("check", "--color", "auto", name).stdout
    assert "\x1b[31m" in run("check", "--color", "always", name).stdout
    assert "\x1b[" not in run("check", "--color", "always", "--format", "json", name).stdout


@pytest.mark.parametrize("args, message", [
    (["check"], "rl1c check: error: the following arguments are required: PATH"),
    (["check", "--format", "xml", "a.rob"], "invalid choice: 'xml'"),
    (["check", "--color", "sometimes", "a.rob"], "invalid choice: 'sometimes'"),
    (["check", "--form", "json", "a.rob"], "unrecognized arguments: --form"),  # no abbreviations
    (["explain"], "give a code, as in `rl1c explain E0101`, or --list"),
    (["explain", "E0101", "--list"], "give a code, as in `rl1c explain E0101`, or --list"),
    (["--bogus"], "rl1c: error: unrecognized arguments: --bogus"),
])
def test_usage_problems_exit_2_with_the_usage_and_what_is_wrong(
    args: list[str], message: str,
) -> None:
    result = run(*args)
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr.startswith("usage: rl1c")
    assert message in result.stderr


def test_options_may_come_between_files(tmp_path: Path) -> None:
    first, second = write(tmp_path, "A=\n", "first.rob"), write(tmp_path, "B=\n", "second.rob")
    result = run("check", first, "--format", "json", second)
    assert result.exit_code == 1
    assert [item["file"] for item in json.loads(result.stdout)] == [first, second]


def test_version_and_help() -> None:
    shown = run("--version")
    assert (shown.exit_code, shown.stdout) == (0, f"rl1c, version {version('rl1')}\n")
    helped = run("--help")
    assert helped.exit_code == 0
    for name in ("check", "compile", "explain", "dis", "asm", "fmt", "run"):
        assert f"\n    {name} " in helped.stdout
    bare = run()  # no command at all: the same help, as a usage problem
    assert (bare.exit_code, bare.stdout, bare.stderr) == (2, "", helped.stdout)
    check_help = run("check", "-h")
    assert check_help.exit_code == 0
    assert "--format {human,concise,json,sarif}" in check_help.stdout


@pytest.mark.parametrize("columns", [60, 80, 120])
def test_help_fits_the_terminal_width(columns: int) -> None:
    """The width comes from $COLUMNS, as shutil would find it (cli.py avoids shutil)."""
    lines = rl1c("check", "--help", env={"COLUMNS": str(columns)}).stdout.splitlines()
    assert max(len(line) for line in lines) <= columns - 2
    assert max(len(line) for line in lines) > columns - 20  # the width is used, not fixed


# Unreadable files: E0100 in the chosen format, exit 2 ---------------------------------


def test_a_missing_file_is_reported_after_the_others(tmp_path: Path) -> None:
    good = write(tmp_path, "A=\n")
    status, items = check_json("missing.rob", good)
    assert status == 2
    assert [(i["file"], i["code"]) for i in items] == [("missing.rob", "E0100"), (good, "E0101")]
    assert "no such file" in items[0]["message"]
    human = run("check", "missing.rob").stdout
    assert human.startswith("error[E0100]: cannot read the source file `missing.rob`: no such "
                            "file\n --> missing.rob\n  |\n  = help: check the name, and the "
                            "folder rl1c runs in\n")


@pytest.mark.parametrize("data, says", [
    (b"A=1\x00\x01\x02", "binary"),
    (bytes(range(256)) * 4, "binary"),
    (b"A=1 '\x81\x20\xff\n", "neither UTF-8 nor Shift-JIS"),
])
def test_binary_and_undecodable_files_are_e0100(tmp_path: Path, data: bytes, says: str) -> None:
    status, items = check_json(write(tmp_path, data))
    assert status == 2
    assert [i["code"] for i in items] == ["E0100"]
    assert says in items[0]["message"]


# Text of every shape ------------------------------------------------------------------


def test_shift_jis_comments_are_read(tmp_path: Path) -> None:
    assert run("check", str(CP932_COMMENTS)).exit_code == 0
    # An error after a Shift-JIS comment has the right line, and its line shows as text.
    data = CP932_COMMENTS.read_bytes() + "A=% ' 未完成\r\n".encode("cp932")
    result = run("check", write(tmp_path, data))
    assert result.exit_code == 1
    assert "7 | A=% ' 未完成\n" in result.stdout


@pytest.mark.parametrize("line_end", ["\r\n", "\r", "\n"])
def test_any_line_end_counts_lines_alike(tmp_path: Path, line_end: str) -> None:
    name = write(tmp_path, line_end.join(["A=1", "B=+", "C=3"]) + line_end)
    status, items = check_json(name)
    assert (status, items[0]["line"], items[0]["column"]) == (1, 2, 3)
    assert "\r" not in run("check", name).stdout


@pytest.mark.parametrize("text", ["", "\n", "A=1", "' only a comment", "\t\n  \n"])
def test_empty_and_unterminated_files_are_fine(tmp_path: Path, text: str) -> None:
    result = run("check", write(tmp_path, text))
    assert result.exit_code == 0
    assert "error" not in result.stdout.replace("0 errors", "")


def test_a_megabyte_line_is_checked_and_shown_briefly(tmp_path: Path) -> None:
    comment = write(tmp_path, "A=1 '" + "x" * 1_000_000 + "\n", "comment.rob")
    assert run("check", comment).exit_code == 0
    word = write(tmp_path, "A" * 1_000_000 + "\n", "word.rob")
    result = run("check", word)
    assert result.exit_code == 1
    assert max(len(line) for line in result.stdout.splitlines()) < 1000


@pytest.mark.parametrize("code", ["A=1" + "+1" * 250_000, "B=2;" * 250_000])
def test_a_megabyte_line_of_code_is_refused_before_it_is_scanned(tmp_path: Path,
                                                                  code: str) -> None:
    # Checking it would take a gigabyte (language.md 3.4): E0106, and nothing else.
    result = run("check", write(tmp_path, code + "\n(END)\n"), "--format", "json")
    assert result.exit_code == 1
    assert [(d["code"], d["line"]) for d in json.loads(result.stdout)] == [("E0106", 1)]


@pytest.mark.parametrize("code", ["A=10" + "+1" * 9_998, "B=2;" * 5_000])
def test_a_line_of_the_longest_length_read_is_checked(tmp_path: Path, code: str) -> None:
    assert len(code) == 20_000
    result = run("check", write(tmp_path, code + "\n(END)\n"), "--format", "json")
    assert result.exit_code == 0
    assert "E01" not in result.stdout


# Never a traceback ---------------------------------------------------------------------

_FRAGMENTS = [
    "A", "z", "@", "=", "+", "-", "<", ">", "&", "|", "^", "++", "--", "1", "-5", "32768",
    "$FF", "$", "#10", "#1", ":10", ":96", ":1", "?A=", "?b>", "(", ")", ",", ";", " ", "\t",
    "(MOV 3,3)", "(MVI 1,1,50)", "(TRC 3)", "(IMG)", "(CAM P c)", "(ULT A)", "(KYO)",
    "(END)", "(FRE)", "(TIM 5)", "'", "' コメント", "\n", "\r\n", "\r", "Ａ", "\u3000", "\x1b",
]
rl1_like = st.lists(st.sampled_from(_FRAGMENTS), max_size=60).map("".join)
any_text = st.text(alphabet=st.characters(exclude_categories=["Cs"]), max_size=300)


def assert_well_formed(result: Result, output_format: str) -> None:
    assert result.exit_code in (0, 1, 2), result.stdout + result.stderr
    assert "Traceback" not in result.stdout + result.stderr
    if output_format == "json":
        assert isinstance(json.loads(result.stdout), list)
    elif output_format == "sarif":
        assert sarif_problems(json.loads(result.stdout)) == []


@settings(max_examples=100, deadline=None)
@given(st.one_of(rl1_like, any_text), st.sampled_from(["human", "json", "sarif"]))
def test_any_text_file_gets_a_report(
    tmp_path_factory: pytest.TempPathFactory, text: str, output_format: str
) -> None:
    path = tmp_path_factory.getbasetemp() / "any_text.rob"
    path.write_text(text, encoding="utf-8", newline="")
    result = run("check", "--format", output_format, str(path))
    assert_well_formed(result, output_format)
    if output_format == "json":
        # Text is never "unreadable", unless a NUL byte marks it as a binary file.
        unreadable = "E0100" in {item["code"] for item in json.loads(result.stdout)}
        assert unreadable == ("\x00" in text)


@settings(max_examples=100, deadline=None)
@given(st.binary(max_size=300), st.sampled_from(["human", "json", "sarif"]))
def test_any_bytes_get_a_report(
    tmp_path_factory: pytest.TempPathFactory, data: bytes, output_format: str
) -> None:
    path = tmp_path_factory.getbasetemp() / "any_bytes.rob"
    path.write_bytes(data)
    assert_well_formed(run("check", "--format", output_format, str(path)), output_format)
    assert_well_formed(run("check", "--format", output_format, "-", stdin=data), output_format)


def test_an_internal_error_is_a_short_message_and_exit_3(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(text: str) -> list[Diagnostic]:
        raise KeyError("no such rule")

    monkeypatch.setattr(analysis, "diagnose_compactly", broken)
    monkeypatch.delenv("RL1C_BACKTRACE", raising=False)
    result = run("check", write(tmp_path, "A=1\n"))
    assert result.exit_code == 3
    assert result.stderr.startswith("rl1c: internal error: KeyError: 'no such rule'\n")
    assert "This is a bug in rl1c" in result.stderr
    assert "Traceback" not in result.stdout + result.stderr
    debugging = rl1c("check", write(tmp_path, "A=1\n"), env={"RL1C_BACKTRACE": "1"})
    assert debugging.exit_code == 3
    assert debugging.stderr.startswith("Traceback (most recent call last):\n")
    assert "in broken\n" in debugging.stderr and "This is a bug in rl1c" in debugging.stderr


def test_ctrl_c_ends_with_a_short_message_and_the_shells_status(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def interrupted(text: str) -> list[Diagnostic]:
        raise KeyboardInterrupt

    monkeypatch.setattr(analysis, "diagnose_compactly", interrupted)
    result = run("check", write(tmp_path, "A=1\n"))
    assert (result.exit_code, result.stdout, result.stderr) == (130, "", "rl1c: interrupted\n")


def test_a_reader_that_stops_early_ends_the_output_quietly() -> None:
    # `rl1c fmt - <x.rob | head -1` when head is gone before rl1c writes: the reader's end
    # of the pipe is closed before rl1c has its input, so its first write fails.
    command = [str(Path(sys.executable).with_name("rl1c")), "fmt", "-"]
    with subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE) as process:
        assert process.stdout is not None and process.stdin is not None
        process.stdout.close()
        _, errors = process.communicate(b"A = 1\n")
    assert (process.returncode, errors) == (1, b"")  # 0 had the output been read



@pytest.mark.parametrize("output_format", ["human", "json", "sarif"])
def test_a_report_streamed_onto_a_closed_pipe_or_a_full_disk_ends_cleanly(
        tmp_path: Path, output_format: str) -> None:
    # The report is written a diagnostic at a time (issue 23, item 10): a reader gone
    # after the first lines, or a disk full in the middle, ends as when it was one write.
    path = write(tmp_path, "A=1 B=2\n" * 3000)
    command = [str(Path(sys.executable).with_name("rl1c")), "check", "--format",
               output_format, path]
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE) as process:
        assert process.stdout is not None
        process.stdout.read(100)
        process.stdout.close()
        _, errors = process.communicate()
    assert (process.returncode, errors) == (1, b"")
    if not Path("/dev/full").exists():
        return
    with open("/dev/full", "wb") as full:
        ended = subprocess.run(command, stdout=full, stderr=subprocess.PIPE, check=False)
    assert ended.returncode == 2
    assert ended.stderr.decode().startswith("rl1c: error: cannot write the output: No space")

# rl1c explain ----------------------------------------------------------------------------


def test_explain_prints_the_explanation_whatever_the_case() -> None:
    upper, lower = run("explain", "E0101"), run("explain", "e0101")
    assert upper.exit_code == lower.exit_code == 0
    assert upper.stdout == lower.stdout == CODES["E0101"].explanation()


def test_explain_an_unknown_code_says_how_to_list_them() -> None:
    result = run("explain", "E9999")
    assert result.exit_code == 2
    assert "`E9999` is not a diagnostic code" in result.stderr
    assert "rl1c explain --list" in result.stderr


def test_explain_list_shows_every_code_with_its_title() -> None:
    result = run("explain", "--list")
    assert result.exit_code == 0
    assert result.stdout.splitlines() == [f"{code}  {info.title}" for code, info in CODES.items()]


@pytest.mark.parametrize("code", list(CODES))
def test_every_code_has_an_explanation_titled_as_in_the_catalogue(code: str) -> None:
    explanation = CODES[code].explanation()
    assert explanation.splitlines()[0] == f"# {code}: {CODES[code].title}"
    assert re.search(r"```.*```", explanation, re.DOTALL), "an example is missing"


def test_a_terminal_that_cannot_show_a_character_gets_an_escape(tmp_path: Path) -> None:
    result = rl1c("check", write(tmp_path, "A=％\n"), encoding="latin-1")
    assert result.exit_code == 1
    assert "1 | A=\\uff05\n" in result.stdout
