"""The formatter (spec/language.md, section 11) and `rl1c fmt`.

The central property: formatting never changes what a program means (the formatted text
parses to the same tree, ignoring positions within lines), never loses text, and is
idempotent.
"""

from __future__ import annotations

import errno
import os
import re
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import SAMPLE, TEST_DATA
from support.cli import Result, rl1c

from rl1.compiler.cli import streams
from rl1.compiler.formatter import format_line, format_lines, format_text
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.frontend.source import split_lines
from rl1.compiler.strategies import lines, programs

CP932_COMMENTS = TEST_DATA / "cp932_comments.rob"

# Listing 1 in the canonical layout, written out by hand from the rules of section 11:
# indentation removed (lines 9, 22-24) and trailing `;` dropped (lines 10, 27-29, 39).
SAMPLE_CANONICAL = """\
'SAMPLE.ROB
(CAM Z); (CAM A 90); (CAM D)
(SCN 0); (TRC 3); (MOV 3,3)
:10 A=(IMG)-180; ?A<#10
(MOV 0,0); (TRC 0)
(SCN 4); (IMG); L=x
(SCN 3); (IMG); U=x
A=U-L; ?A>#12
c=205; d=-450; #13
:12 c=579; d=450
:13
(CAM U); (SCN 2); (CAM P c)
@=5; C=c; D=d
:14 (IMG)
a=x-128
b=a<4+a; C=a<3+b>6+C
c=a<7; d=a<3+c>a<7; D=D+d
(CAM P C)
@--; ?@>#14
(STX D); (MOV 1,1)
:20 (IMG)
Y=y-160; ?Y>#29
X=x-60; ?X<#21
X=x-200; ?X>#21
#20
:21 (MOV 0,0); @=-5; D=0
:22 (IMG)
a=x-128
b=a<4+a; C=a<3+b>6+C
c=a<7; d=a<3+c>a<7
(CAM P C); D=D+d; @--
?@>#22
(STX D); (MOV 1,1)
#20
:29 (MOV 0,0); (HLD)
(CAM D); (SCN 0); (STL 75)
(TRC 0); (MOV 1,1)
:40 A=(IMG)-100; ?A<#40
(MOV 0,0); (STR 75); (TRC 3)
(MVI 1,1,50); (MOV 3,3)
:96 (MOV 0,0)
:99
(FRE); (END)
"""


def shape(node: object) -> object:
    """A node as nested tuples without its spans: equal shapes mean the same program."""
    if isinstance(node, ast.Node):
        return (type(node).__name__, *(
            shape(value) for _, value in node.fields() if not isinstance(value, ast.Span)))
    if isinstance(node, tuple):
        return tuple(shape(item) for item in node)
    return node


def meaning(text: str) -> tuple[object, list[tuple[str, int]]]:
    """The program's lines without trailing blank ones, and its syntax diagnostics."""
    program, diagnostics = parse_program(text)
    kept = list(program.lines)
    while kept and kept[-1].ok and not (kept[-1].label or kept[-1].statements
                                         or kept[-1].comment):
        kept.pop()
    return shape(tuple(kept)), [(d.code, d.span.line) for d in diagnostics]


# Any text: generated programs, with lines of arbitrary text (mostly syntax errors) mixed in.
any_line = st.one_of(lines(), lines(), st.text(
    st.characters(codec="utf-8", blacklist_characters="\r\n"), max_size=20))
documents = st.one_of(
    programs(),
    st.lists(any_line, max_size=12).map("\n".join),
    st.lists(any_line, max_size=12).map(lambda ls: "\r\n".join(ls) + "\r\n"),
)


# Properties ---------------------------------------------------------------------------


@settings(max_examples=150, deadline=None)
@given(documents)
def test_formatting_keeps_the_meaning_and_every_error_line(text: str) -> None:
    assert meaning(format_text(text)) == meaning(text)


@settings(max_examples=150, deadline=None)
@given(documents)
def test_formatting_is_idempotent(text: str) -> None:
    once = format_text(text)
    assert format_text(once) == once
    assert format_lines(once, 1, len(split_lines(once))) == []


@settings(max_examples=100, deadline=None)
@given(documents)
def test_comments_are_kept_character_for_character(text: str) -> None:
    def comments(source: str) -> list[str]:
        return [line.comment.text for line in parse_program(source)[0].lines if line.comment]

    assert comments(format_text(text)) == comments(text)


@settings(max_examples=100, deadline=None)
@given(programs())
def test_one_line_out_per_line_in_with_the_first_line_end(text: str) -> None:
    formatted = format_text(text)
    original_lines = split_lines(text)
    while original_lines and not format_line(original_lines[-1]):
        original_lines.pop()
    assert len(split_lines(formatted)) == len(original_lines)
    first = re.search(r"\r\n|\r|\n", text)
    first_end = first.group() if first else "\n"
    if formatted:
        assert formatted.endswith(first_end)
        assert formatted.count(first_end) == len(original_lines)


@settings(max_examples=100, deadline=None)
@given(documents, st.integers(0, 14), st.integers(0, 14))
def test_range_formatting_touches_only_its_lines_and_agrees_with_the_whole(
        text: str, first: int, last: int) -> None:
    original = split_lines(text)
    edits = format_lines(text, first, last)
    edited = list(original)
    for edit in edits:
        assert first <= edit.span.line <= last
        assert (edit.span.column, edit.span.end_line) == (1, edit.span.line)
        assert edit.span.end_column == len(original[edit.span.line - 1]) + 1
        edited[edit.span.line - 1] = edit.text
    assert format_text("\n".join(edited)) == format_text("\n".join(original))


# Examples -----------------------------------------------------------------------------


def test_listing_1_formats_to_the_canonical_text() -> None:
    assert format_text(SAMPLE.read_text(encoding="utf-8")) == SAMPLE_CANONICAL


@pytest.mark.parametrize(("line", "canonical"), [
    ("   A = B + 5 ;; ", "A=B+5"),
    (":10A=1", ":10 A=1"),
    (":12 c=579; d=450;", ":12 c=579; d=450"),
    (":10 ;", ":10"),
    (";", ""),
    ("\t \t", ""),
    ("(MVI 1 1 50)", "(MVI 1,1,50)"),
    ("( MOV 3 , -3 )", "(MOV 3,-3)"),
    ("(CAM A,90); (CAM P  c)", "(CAM A 90); (CAM P c)"),
    ("(CAM A,-5)", "(CAM A,-5)"),  # `(CAM A -5)` would read as A minus 5
    ("A=B- -5", "A=B--5"),
    ("?A < #10", "?A<#10"),
    ("@ --", "@--"),
    ("x=$aa55&$0F", "x=$aa55&$0F"),
    ("(mov 3,3)", "(mov 3,3)"),
    ("A=1'c", "A=1 'c"),
    ("    '  作業台に接近  ", "'  作業台に接近  "),
    (":13   ' 全角　の　コメント", ":13 ' 全角　の　コメント"),
    ("  A=-B  ' syntax error", "  A=-B  ' syntax error"),
    ("  AB=1", "  AB=1"),
])
def test_canonical_lines(line: str, canonical: str) -> None:
    assert format_line(line) == canonical


@pytest.mark.parametrize(("text", "formatted"), [
    ("", ""),
    ("\n\n  \n", ""),
    ("A=1", "A=1\n"),
    ("A = 1\r\nB = 2\r\n", "A=1\r\nB=2\r\n"),
    ("A = 1\rB = 2", "A=1\rB=2\r"),
    ("A=1\r\nB=2\nC=3\r", "A=1\r\nB=2\r\nC=3\r\n"),
    ("A=1\n\n\nB=2\n\n\n", "A=1\n\n\nB=2\n"),
])
def test_line_ends_and_blank_lines(text: str, formatted: str) -> None:
    assert format_text(text) == formatted


# rl1c fmt -----------------------------------------------------------------------------


def run(*args: str, stdin: bytes = b"") -> Result:
    return rl1c("fmt", *args, stdin=stdin)


def write(tmp_path: Path, data: bytes, name: str = "prog.rob") -> Path:
    path = tmp_path / name
    path.write_bytes(data)
    return path


def test_fmt_rewrites_files_in_place(tmp_path: Path) -> None:
    messy = write(tmp_path, b"  A = 1 ;\r\n:10 (MOV 3 3)\r\n", "messy.rob")
    tidy = write(tmp_path, b"B=2\n", "tidy.rob")
    tidy_time = tidy.stat().st_mtime_ns
    result = run(str(messy), str(tidy))
    assert result.exit_code == 0, result.output
    assert messy.read_bytes() == b"A=1\r\n:10 (MOV 3,3)\r\n"
    assert tidy.stat().st_mtime_ns == tidy_time  # an unchanged file is not rewritten
    assert sorted(p.name for p in tmp_path.iterdir()) == ["messy.rob", "tidy.rob"]


def test_fmt_check_lists_what_would_change_and_changes_nothing(tmp_path: Path) -> None:
    messy = write(tmp_path, b"A = 1\n", "messy.rob")
    tidy = write(tmp_path, b"A=1\n", "tidy.rob")
    result = run("--check", str(messy), str(tidy))
    assert result.exit_code == 1
    assert result.stdout == f"{messy}\n"
    assert messy.read_bytes() == b"A = 1\n"
    assert run("--check", str(tidy)).exit_code == 0


def test_fmt_diff_prints_a_unified_diff_and_changes_nothing(tmp_path: Path) -> None:
    messy = write(tmp_path, b"'ok\nA = 1\n")
    result = run("--diff", str(messy))
    assert result.exit_code == 1  # as `ruff format --diff`: a change to make is a failure
    assert "-A = 1\n+A=1\n" in result.stdout
    assert result.stdout.startswith(f"--- {messy}\n+++ {messy} (formatted)\n")
    assert messy.read_bytes() == b"'ok\nA = 1\n"


def test_fmt_dash_formats_standard_input_to_standard_output() -> None:
    result = run("-", stdin="A = 1 ' コメント\n".encode())
    assert result.exit_code == 0
    assert result.stdout_bytes == "A=1 ' コメント\n".encode()


def test_fmt_reports_an_unreadable_file_and_goes_on(tmp_path: Path) -> None:
    messy = write(tmp_path, b"A = 1\n")
    binary = write(tmp_path, b"A=1\x00", "binary.rob")
    result = run(str(tmp_path / "missing.rob"), str(binary), str(messy))
    assert result.exit_code == 2
    assert "missing.rob: no such file" in result.stderr
    assert "binary file" in result.stderr
    assert "Traceback" not in result.output
    assert messy.read_bytes() == b"A=1\n"


def test_fmt_keeps_a_cp932_file_in_cp932(tmp_path: Path) -> None:
    original = CP932_COMMENTS.read_bytes()
    assert original.endswith(b"\r\n")
    copy = write(tmp_path, original + b"  A = 1 ;   ' \x8a\xbf\x8e\x9a\r\n")  # ' 漢字
    assert run(str(copy)).exit_code == 0
    data = copy.read_bytes()
    assert data.endswith(b"\r\nA=1 ' \x8a\xbf\x8e\x9a\r\n")
    assert data.decode("cp932") == format_text(original.decode("cp932") + "  A = 1 ;   ' 漢字\r\n")


def test_fmt_keeps_a_byte_order_mark_and_follows_a_symbolic_link(tmp_path: Path) -> None:
    target = write(tmp_path, b"\xef\xbb\xbfA = 1 ' \xe3\x81\x82\n", "target.rob")
    link = tmp_path / "link.rob"
    link.symlink_to(target)
    assert run(str(link)).exit_code == 0
    assert link.is_symlink()
    assert target.read_bytes() == b"\xef\xbb\xbfA=1 ' \xe3\x81\x82\n"


def test_fmt_reports_a_file_it_cannot_write(tmp_path: Path,
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    def disk_full(path: object, data: bytes, *, force: bool = False) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(streams, "write_atomically", disk_full)
    messy = write(tmp_path, b"A = 1\n")
    result = run(str(messy))
    assert result.exit_code == 2
    assert f"cannot write `{messy}`: No space left on device" in result.stderr
    assert messy.read_bytes() == b"A = 1\n"


def test_fmt_sums_up_what_it_changed_on_standard_error(tmp_path: Path) -> None:
    messy = write(tmp_path, b"A = 1\n", "messy.rob")
    tidy = write(tmp_path, b"A=1\n", "tidy.rob")
    checked = run("--check", str(messy), str(tidy))
    assert checked.stderr == "1 file would be reformatted, 1 file already formatted\n"
    done = run(str(messy), str(tidy), str(tmp_path / "gone.rob"))
    assert done.exit_code == 2
    assert done.stderr.endswith(
        "1 file reformatted, 1 file left unchanged, 1 file could not be formatted\n")
    again = run(str(messy), str(tidy))
    assert (again.exit_code, again.stderr) == (0, "0 files reformatted, 2 files left unchanged\n")


def test_fmt_formats_every_rob_file_below_a_folder(tmp_path: Path) -> None:
    first = write(tmp_path, b"A = 1\n", "a.rob")
    (tmp_path / "sub").mkdir()
    second = write(tmp_path, b"B = 2\n", "sub/B.ROB")
    other = write(tmp_path, b"C = 3\n", "sub/notes.txt")
    diff = run("--diff", str(tmp_path))
    assert diff.exit_code == 1
    assert [line for line in diff.stdout.splitlines() if line.startswith("---")] == [
        f"--- {first}", f"--- {second}"]
    assert run(str(tmp_path)).exit_code == 0
    assert (first.read_bytes(), second.read_bytes(), other.read_bytes()) == (
        b"A=1\n", b"B=2\n", b"C = 3\n")
    assert run("--check", str(tmp_path)).exit_code == 0
