"""Control over `rl1c check`'s diagnostics: the concise format, folders, the summary line,
--select/--ignore, --warnings-as-errors, --fix/--diff and the project file rl1.toml."""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path
from typing import Any

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from support import TEST_DATA
from support.cli import Result, rl1c

from rl1.compiler.analysis import analyze, fix
from rl1.compiler.frontend.source import decode
from rl1.compiler.strategies import programs

# W0603 (no END) and W0701 (runs off its end moving), both on line 1, both with fixes.
MOVING = "(MOV 3,3)\n"
# E0203 on line 2 (no :50); W0301 on line 1 (mode 3, no :97).
BROKEN = "(TRC 3); (MVI 3,3,100)\n?A=#50\n(END)\n"
CLEAN = "A=1\n(END)\n"


def write(folder: Path, name: str, text: str | bytes) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(text, str):
        path.write_text(text, encoding="utf-8", newline="")
    else:
        path.write_bytes(text)
    return path


def check(*args: str | Path, stdin: bytes = b"") -> Result:
    return rl1c("check", *args, stdin=stdin)


def codes_in(result: Result) -> list[tuple[str, str]]:
    """(file name, code) of each diagnostic in a JSON report."""
    return [(Path(item["file"]).name, item["code"]) for item in json.loads(result.stdout)]


# --format concise and the summary -----------------------------------------------------


def test_concise_is_one_line_per_diagnostic_then_the_summary(tmp_path: Path) -> None:
    broken = write(tmp_path, "broken.rob", BROKEN)
    result = check("--format", "concise", broken, write(tmp_path, "clean.rob", CLEAN))
    assert result.exit_code == 1
    expected = [f"{broken}:{d.span.line}:{d.span.column}: {d.severity.value}[{d.code}]: "
                f"{d.message}" for d in analyze(BROKEN).diagnostics]
    assert [line.split("[")[1][:5] for line in expected] == ["W0301", "E0203"]
    assert result.stdout.splitlines() == [*expected, "2 files checked: 1 error, 1 warning"]


def test_concise_places_an_unreadable_file_at_its_start(tmp_path: Path) -> None:
    result = check("--format", "concise", tmp_path / "gone.rob")
    assert result.exit_code == 2
    assert result.stdout == (f"{tmp_path / 'gone.rob'}:1:1: error[E0100]: "
                             f"cannot read the source file `{tmp_path / 'gone.rob'}`: "
                             "no such file\n"
                             "no file checked: 1 file could not be read\n")


def test_the_summary_counts_every_file_and_machine_formats_have_none(tmp_path: Path) -> None:
    files = [write(tmp_path, "a.rob", MOVING), write(tmp_path, "b.rob", CLEAN),
             write(tmp_path, "c.rob", CLEAN)]
    human = check(*files)
    assert human.exit_code == 0
    assert human.stdout.endswith("\n3 files checked: 0 errors, 2 warnings\n")
    assert check(files[1]).stdout == "1 file checked: 0 errors, 0 warnings\n"
    assert isinstance(json.loads(check("--format", "json", *files).stdout), list)
    assert json.loads(check("--format", "sarif", *files).stdout)["version"] == "2.1.0"


# Folders ---------------------------------------------------------------------------------


def test_a_folder_checks_every_rob_file_below_it_in_order(tmp_path: Path) -> None:
    write(tmp_path, "b.rob", MOVING)
    write(tmp_path, "sub/A.ROB", BROKEN)  # DOS names its files in upper case
    write(tmp_path, "sub/notes.txt", "A=\n")
    write(tmp_path, ".git/hidden.rob", "A=\n")
    write(tmp_path, "sub/.hidden.rob", "A=\n")
    result = check("--format", "json", tmp_path)
    assert result.exit_code == 1
    assert codes_in(result) == [("b.rob", "W0603"), ("b.rob", "W0701"),
                                ("A.ROB", "W0301"), ("A.ROB", "E0203")]
    assert check(tmp_path).stdout.endswith("\n2 files checked: 1 error, 3 warnings\n")


def test_a_link_to_a_folder_and_a_fifo_are_left_out(tmp_path: Path) -> None:
    write(tmp_path, "real/a.rob", CLEAN)
    (tmp_path / "real" / "loop").symlink_to(tmp_path / "real")
    os.mkfifo(tmp_path / "real" / "pipe.rob")  # reading it would wait for a writer
    result = check(tmp_path / "real")
    assert result.stdout == "1 file checked: 0 errors, 0 warnings\n"


def test_a_folder_without_programs_is_said_and_is_no_failure(tmp_path: Path) -> None:
    result = check(tmp_path)
    assert result.exit_code == 0
    assert result.stderr == f"rl1c check: warning: no .rob file under `{tmp_path}`\n"
    assert result.stdout == "0 files checked: 0 errors, 0 warnings\n"


def test_a_folder_that_cannot_be_listed_is_e0100(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    write(tmp_path, "a.rob", CLEAN)
    locked = tmp_path / "locked"
    locked.mkdir()
    scandir = os.scandir

    def refuse(path: Any = ".") -> Any:  # root may list any folder: refuse it here
        if str(path) == str(locked):
            raise PermissionError(13, "Permission denied", str(path))
        return scandir(path)

    monkeypatch.setattr(os, "scandir", refuse)
    result = check("--format", "json", tmp_path)
    assert result.exit_code == 2
    items = json.loads(result.stdout)
    assert [(Path(i["file"]).name, i["code"]) for i in items] == [("locked", "E0100")]
    assert items[0]["message"] == f"cannot list the folder `{items[0]['file']}`: permission denied"


# --select, --ignore, --warnings-as-errors -----------------------------------------------


@pytest.mark.parametrize("args, codes", [
    ([], ["W0603", "W0701", "W0301", "E0203"]),
    (["--select", "W07"], ["W0701", "E0203"]),
    (["--select", "w0603,W0301"], ["W0603", "W0301", "E0203"]),
    (["--select", "W06", "--select", "W03"], ["W0603", "W0301", "E0203"]),
    (["--ignore", "W0603"], ["W0701", "W0301", "E0203"]),
    (["--select", "W0", "--ignore", "W07,W03"], ["W0603", "E0203"]),
    (["--select", "W0701", "--ignore", "W07"], ["E0203"]),  # ignoring wins
])
def test_select_and_ignore_choose_warnings_and_errors_always_show(
    tmp_path: Path, args: list[str], codes: list[str],
) -> None:
    files = [write(tmp_path, "a.rob", MOVING), write(tmp_path, "b.rob", BROKEN)]
    result = check("--format", "json", *args, *files)
    assert result.exit_code == 1
    assert [code for _, code in codes_in(result)] == codes


@pytest.mark.parametrize("args, message", [
    (["--select", "E0101"], "`E0101` names only errors, which are always reported"),
    (["--ignore", "E"], "`E` names only errors"),
    (["--ignore", "W9"], "`W9` is no diagnostic code nor the start of one"),
    (["--select", "W0601,,W0602"], "an empty code in `W0601,,W0602`"),
])
def test_codes_that_select_no_warning_are_usage_errors(tmp_path: Path, args: list[str],
                                                      message: str) -> None:
    result = check(*args, write(tmp_path, "a.rob", MOVING))
    assert (result.exit_code, result.stdout) == (2, "")
    assert result.stderr.startswith("usage: rl1c check")
    assert f"rl1c check: error: argument {args[0]}: {message}" in result.stderr


def test_warnings_as_errors_fails_on_a_warning(tmp_path: Path) -> None:
    moving = write(tmp_path, "a.rob", MOVING)
    assert check(moving).exit_code == 0
    strict = check("--warnings-as-errors", "--format", "json", moving)
    assert strict.exit_code == 1
    assert {(i["code"], i["severity"]) for i in json.loads(strict.stdout)} == {
        ("W0603", "error"), ("W0701", "error")}
    human = check("--warnings-as-errors", moving)
    assert human.stdout.startswith("error[W0603]")
    assert human.stdout.endswith("1 file checked: 2 errors, 0 warnings\n")
    assert check("--warnings-as-errors", "--ignore", "W06,W07", moving).exit_code == 0


# --fix and --diff ------------------------------------------------------------------------


def test_fix_makes_the_fixes_and_reports_what_is_left(tmp_path: Path) -> None:
    program = write(tmp_path, "a.rob", ":5 (mov 3,3)\r\n#05\r\n")
    result = check("--fix", program)
    assert result.exit_code == 0, result.output
    assert program.read_bytes() == b":05 (MOV 3,3)\r\n#05\r\n"
    # What is left has no fix of its own: the loop that never looks at the world.
    assert [d.code for d in analyze(program.read_text(encoding="utf-8")).diagnostics] == [
        "W0604"]
    assert result.stdout.endswith("1 file checked: 0 errors, 1 warning (2 problems fixed)\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.rob"]  # no temporary left


def test_fix_keeps_a_cp932_file_in_cp932_and_a_byte_order_mark(tmp_path: Path) -> None:
    legacy = (TEST_DATA / "cp932_comments.rob").read_bytes() + "(mov 3,3) ' 前進\r\n".encode(
        "cp932")
    cp932 = write(tmp_path, "legacy.rob", legacy)
    bom = write(tmp_path, "bom.rob", b"\xef\xbb\xbf(mov 0,0) ' \xe3\x81\x82\n(END)\n")
    assert check("--fix", "--select", "W05", cp932, bom).exit_code == 0
    assert cp932.read_bytes() == legacy.replace(b"(mov 3,3)", b"(MOV 3,3)")
    assert bom.read_bytes() == b"\xef\xbb\xbf(MOV 0,0) ' \xe3\x81\x82\n(END)\n"


@settings(max_examples=60, deadline=None)
@given(programs(), st.sampled_from(["utf-8", "utf-8-sig", "cp932"]))
def test_fix_writes_what_fix_makes_in_the_files_own_encoding(
    tmp_path_factory: pytest.TempPathFactory, text: str, encoding: str,
) -> None:
    try:
        data = text.encode(encoding)
    except UnicodeEncodeError:
        assume(False)
    before = decode(data)
    path = tmp_path_factory.getbasetemp() / "fixed.rob"
    path.write_bytes(data)
    result = check("--fix", "--format", "json", path)
    assert result.exit_code in (0, 1), result.output
    after = decode(path.read_bytes())
    assert after.text == fix(before.text).text
    assert (after.encoding, after.bom) == (before.encoding, before.bom)


def test_fix_makes_only_the_fixes_of_selected_warnings(tmp_path: Path) -> None:
    program = write(tmp_path, "a.rob", MOVING)
    assert check("--fix", "--unsafe-fixes", "--ignore", "W0603", program).exit_code == 0
    assert program.read_text(encoding="utf-8") == "(MOV 3,3)\n(MOV 0,0)\n"


def test_fix_makes_the_safe_fixes_and_says_how_many_unsafe_ones_it_left(
        tmp_path: Path) -> None:
    program = write(tmp_path, "a.rob", ":5 (TIM 10); (MOVE 3,3)\n(END)\n")
    result = check("--fix", program)
    assert result.exit_code == 1
    assert program.read_text(encoding="utf-8") == ":05 (TIM 10); (MOVE 3,3)\n(END)\n"
    assert result.stdout.endswith(
        "1 file checked: 1 error, 1 warning (1 problem fixed; 2 unsafe fixes not made: "
        "--unsafe-fixes makes them)\n")
    unsafe = check("--fix", "--unsafe-fixes", program)
    assert unsafe.exit_code == 0, unsafe.output
    assert program.read_text(encoding="utf-8") == "(TIM 10); (MOV 3,3)\n(END)\n"
    alone = check("--unsafe-fixes", program)
    assert alone.exit_code == 2 and "give it with one of them" in alone.stderr


def test_fix_refuses_a_read_only_file_unless_forced(tmp_path: Path) -> None:
    program = write(tmp_path, "a.rob", MOVING)
    program.chmod(stat.S_IRUSR | stat.S_IRGRP)
    result = check("--fix", program)
    assert result.exit_code == 2
    assert result.stderr.startswith(f"error[E0100]: cannot write the source file `{program}` to "
                                    "make its fixes: it is read-only; give --force")
    assert program.read_text(encoding="utf-8") == MOVING
    assert "warning[W0603]" in result.stdout  # what the file still has is reported
    assert check("--fix", "--force", program).exit_code == 0
    assert program.read_text(encoding="utf-8") == "(MOV 3,3)\n(END)\n"


def test_diff_shows_what_fix_would_change_and_changes_nothing(tmp_path: Path) -> None:
    program = write(tmp_path, "a.rob", MOVING)
    clean = write(tmp_path, "b.rob", CLEAN)
    result = check("--diff", program, clean)
    assert result.exit_code == 1
    assert result.stdout == (f"--- {program}\n+++ {program} (fixed)\n@@ -1 +1,2 @@\n"
                             " (MOV 3,3)\n+(END)\n")
    assert result.stderr == ("--fix would make 1 fix in 1 file; 1 unsafe fix not made: "
                             "--unsafe-fixes makes it\n")
    unsafe = check("--diff", "--unsafe-fixes", program)
    assert unsafe.stderr == ("--fix --unsafe-fixes would make 1 fix in 1 file; 1 fix left for "
                             "another run to make\n")
    assert program.read_text(encoding="utf-8") == MOVING
    nothing = check("--diff", clean)
    assert (nothing.exit_code, nothing.stdout) == (0, "")


def test_diff_reads_standard_input_and_fix_refuses_it(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = check("--diff", "-", stdin=MOVING.encode())
    assert result.exit_code == 1 and "+(END)" in result.stdout
    refused = check("--fix", "-", stdin=MOVING.encode())
    assert refused.exit_code == 2
    assert "--fix rewrites files, and standard input is none" in refused.stderr
    assert list(tmp_path.iterdir()) == []


# rl1.toml --------------------------------------------------------------------------------


def test_the_nearest_project_file_sets_the_options(tmp_path: Path) -> None:
    write(tmp_path, "rl1.toml", '[check]\nignore = ["W0603"]\nwarnings-as-errors = true\n')
    write(tmp_path, "team/sub/rl1.toml", '[check]\nselect = ["W06"]\n')
    top = write(tmp_path, "team/a.rob", MOVING)
    deep = write(tmp_path, "team/sub/deeper/b.rob", MOVING)
    result = check("--format", "json", top, deep)
    assert result.exit_code == 1
    assert [(i["code"], i["severity"]) for i in json.loads(result.stdout)] == [
        ("W0701", "error"), ("W0603", "warning")]


def test_a_project_file_may_start_with_a_byte_order_mark(tmp_path: Path) -> None:
    write(tmp_path, "rl1.toml", '\ufeff[check]\nignore = ["W0603", "W0701"]\n'.encode())
    assert check(write(tmp_path, "a.rob", MOVING)).exit_code == 0  # refused before


def test_a_project_files_hexadecimal_integer_of_any_length_is_an_error_with_its_line(
        tmp_path: Path) -> None:
    # tomllib reads 0x integers without Python's 4300-digit bound: it was an internal error.
    project = write(tmp_path, "rl1.toml", "[check]\nignore = 0x" + "f" * 5000 + "\n")
    result = check(write(tmp_path, "a.rob", MOVING))
    assert result.exit_code == 2
    assert (": check.ignore: a number of more than 4300 digits; no value here is near that "
            f"long\n --> {project}:2\n") in result.stderr


def test_options_given_win_over_the_project_file(tmp_path: Path) -> None:
    write(tmp_path, "rl1.toml", '[check]\nselect = ["W06"]\nwarnings-as-errors = true\n')
    program = write(tmp_path, "a.rob", MOVING)
    result = check("--format", "json", "--select", "W07", "--no-warnings-as-errors", program)
    assert result.exit_code == 0
    assert [(i["code"], i["severity"]) for i in json.loads(result.stdout)] == [
        ("W0701", "warning")]


def test_isolated_reads_no_project_file(tmp_path: Path) -> None:
    write(tmp_path, "rl1.toml", "[check\n")  # broken, and not even read
    program = write(tmp_path, "a.rob", MOVING)
    assert check(program).exit_code == 2
    result = check("--isolated", "--format", "json", "--ignore", "W0603", program)
    assert result.exit_code == 0
    assert [code for _, code in codes_in(result)] == ["W0701"]


def test_standard_input_takes_the_working_directorys_project_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    write(tmp_path, "rl1.toml", '[check]\nignore = ["W"]\n')
    monkeypatch.chdir(tmp_path)
    assert check("-", stdin=MOVING.encode()).stdout == "1 file checked: 0 errors, 0 warnings\n"


# What follows "is not valid: ", and the line of ` --> rl1.toml:LINE` (None: the file).
@pytest.mark.parametrize("content, line, says", [
    ("[check\n", 1, "invalid TOML: "),
    ('[check]\nselct = ["W06"]\n',
     2, "check.selct: unknown key; did you mean select? (expected one of select, ignore, "
     "warnings-as-errors)"),
    ('[lint]\nselect = ["W06"]\n', 1, "lint: unknown key; expected one of check"),
    ("check = 3\n", 1, "check: expected a table, found 3"),
    ('[check]\nselect = "W06"\n',
     2, 'check.select: expected a list of codes, such as ["W06'),
    ('[check]\nignore = ["E0101"]\n', 2, "check.ignore: `E0101` names only errors"),
    ("[check]\nwarnings-as-errors = 1\n",
     2, "check.warnings-as-errors: expected true or false"),
    # Every number goes through the one bounded reader: an internal error before.
    ("[check]\nwarnings-as-errors = " + "9" * 5000 + "\n",
     2, "check.warnings-as-errors: a number of more than 4300 digits"),
    ("[check]\nselect = [" + "1" * 4000 + "]\n", 2, "found a number of 4000 digits"),
    (b"[check]\n# \xff\n", None, "not UTF-8 text"),
    ("x = " + "[" * 100_000 + "]" * 100_000 + "\n", None, "nested too deeply"),
])
def test_a_bad_project_file_stops_the_check_with_where_and_why(
    tmp_path: Path, content: str | bytes, line: int | None, says: str,
) -> None:
    project = write(tmp_path, "rl1.toml", content)
    result = check(write(tmp_path, "a.rob", MOVING))
    assert (result.exit_code, result.stdout) == (2, "")
    assert result.stderr.startswith("error[E0100]: the project file is not valid: ")
    assert says in result.stderr
    assert f"\n --> {project}{'' if line is None else f':{line}'}\n" in result.stderr
    assert "= help: correct the file" in result.stderr
    assert "Traceback" not in result.stderr


def test_an_unreadable_project_file_is_said(tmp_path: Path) -> None:
    (tmp_path / "rl1.toml").mkdir()  # a folder of that name is no project file
    assert check(write(tmp_path, "a.rob", CLEAN)).exit_code == 0
    project = write(tmp_path, "sub/rl1.toml", "[check]\n")
    project.chmod(0)
    if os.access(project, os.R_OK):
        pytest.skip("this user reads any file (root)")
    result = check(write(tmp_path, "sub/a.rob", CLEAN))
    assert result.exit_code == 2
    assert result.stderr.startswith(f"error[E0100]: cannot read the project file `{project}`: "
                                    "permission denied\n")
