"""Hostile test files, outputs and sweeps that once ended badly, each held here: a test
file naming a FIFO (rl1c test waited forever), a path with a NUL character (an
internal error), a name with an escape sequence (written to the terminal), a symbolic
link loop (a message ending in "; "); --junit onto a file the tests read (replaced),
`-` (a file named `-`), a folder (found after every test ran) or a read-only file
(which said to give a --force that rl1c test did not have); and a --sweep whose N had
leading zeros (read as its first six digits)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from support.cli import rl1c

from rl1.compiler.cli.project_template import FILES
from rl1.compiler.sweep import parse_axis

RL1C = Path(sys.executable).with_name("rl1c")


def project(folder: Path, program: str = "main.rob", extra: str = "") -> Path:
    """The files of `rl1c new`, and t.tests.toml, a test of `program` on the sensors."""
    for name, text in FILES.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text, encoding="utf-8")
    tests = folder / "t.tests.toml"
    tests.write_text(f'[[test]]\nname = "it ends"\nprogram = "{program}"\n'
                     f'sensors = "main.sensors.toml"\n{extra}', encoding="utf-8")
    return tests


def test_a_program_that_is_a_fifo_is_an_error_not_a_wait(tmp_path: Path) -> None:
    tests = project(tmp_path, "pipe.rob")
    os.mkfifo(tmp_path / "pipe.rob")
    done = subprocess.run([str(RL1C), "test", str(tests), "--jobs", "1"], timeout=120,
                          capture_output=True, text=True, check=False)
    assert done.returncode == 1, done.stderr
    assert f"{tmp_path / 'pipe.rob'} is not a regular file" in done.stdout
    assert "Traceback" not in done.stdout + done.stderr


@pytest.mark.parametrize("key", ["program", "world", "sensors"])
def test_a_path_with_a_nul_character_is_refused_with_its_line(tmp_path: Path,
                                                               key: str) -> None:
    tests = project(tmp_path)
    text = tests.read_text(encoding="utf-8").replace(f'{key} = "', f'{key} = "x\\u0000', 1)
    if key == "world":
        text = text.replace('sensors = "main.sensors.toml"\n', 'world = "x\\u0000.toml"\n')
    tests.write_text(text, encoding="utf-8")
    result = rl1c("test", tests)
    assert result.exit_code == 2, result.output
    line = 3 if key == "program" else 4
    assert f"is not valid: test[0].{key}: holds the control character U+0000" \
        in result.stderr
    assert f" --> {tests}:{line}\n" in result.stderr  # the place, on the arrow's line


def test_a_name_with_an_escape_sequence_never_reaches_the_terminal(tmp_path: Path) -> None:
    tests = project(tmp_path)
    text = tests.read_text(encoding="utf-8").replace('"it ends"', '"it \\u001b[2J ends"')
    tests.write_text(text + "expect.variables = { A = 5 }\n", encoding="utf-8")
    result = rl1c("test", tests)
    assert result.exit_code == 1
    assert "t.tests.toml: it \ufffd[2J ends" in result.stdout
    assert "\x1b" not in result.output


def test_a_symbolic_link_loop_says_what_happened_without_a_dangling_help(
        tmp_path: Path) -> None:
    tests = project(tmp_path, "loop.rob")
    (tmp_path / "loop.rob").symlink_to("loop.rob")
    result = rl1c("test", tests, "--jobs", "1")
    assert result.exit_code == 1
    said = next(line for line in result.stdout.splitlines() if "loop.rob" in line
                and "cannot read" in line)
    assert "symbolic links" in said and not said.rstrip().endswith(";"), said


@pytest.mark.parametrize("input_name", ["t.tests.toml", "main.rob", "main.sensors.toml"])
def test_junit_onto_a_file_the_tests_read_is_refused_before_any_test(
        tmp_path: Path, input_name: str) -> None:
    tests = project(tmp_path)
    before = (tmp_path / input_name).read_bytes()
    result = rl1c("test", tests, "--junit", tmp_path / input_name)
    assert result.exit_code == 2
    assert f"`{tmp_path / input_name}` is the " in result.stderr
    assert " itself: give another path for the JUnit XML" in result.stderr
    assert result.stdout == ""  # no test ran
    assert (tmp_path / input_name).read_bytes() == before


@pytest.mark.parametrize("target", ["-", "", "folder"])
def test_junit_to_standard_output_or_a_folder_is_refused_before_any_test(
        tmp_path: Path, target: str, monkeypatch: pytest.MonkeyPatch) -> None:
    tests = project(tmp_path)
    (tmp_path / "folder").mkdir()
    monkeypatch.chdir(tmp_path)
    result = rl1c("test", tests, "--junit", target)
    assert result.exit_code == 2
    assert result.stdout == ""
    assert "rl1c test: error: --junit " in result.stderr
    assert not (tmp_path / "-").exists()


def test_a_read_only_junit_file_is_replaced_with_the_force_it_asks_for(
        tmp_path: Path) -> None:
    tests = project(tmp_path)
    junit = tmp_path / "report.xml"
    junit.write_text("old")
    junit.chmod(0o444)
    refused = rl1c("test", tests, "--junit", junit)
    assert refused.exit_code == 2 and "give --force" in refused.stderr
    assert junit.read_text() == "old"
    forced = rl1c("test", tests, "--junit", junit, "--force")
    assert forced.exit_code == 0, forced.output
    assert junit.read_text().startswith("<?xml")


@pytest.mark.parametrize(("text", "count"), [("x=0:1:0000015", 15), ("x=0:1:010000", 10000),
                                             ("x=1:1:0001", 1)])
def test_a_sweeps_count_with_leading_zeros_is_the_number_written(text: str,
                                                                  count: int) -> None:
    assert parse_axis(text).count == count


@pytest.mark.parametrize("text", ["x=0:1:000", "x=0:1:0010001", "x=0:1:" + "9" * 5000])
def test_a_sweeps_count_outside_its_range_is_refused_whatever_its_zeros(text: str) -> None:
    with pytest.raises(ValueError, match="N is the number of points"):
        parse_axis(text)
