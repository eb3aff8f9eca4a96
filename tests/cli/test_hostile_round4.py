"""Hostile input, round four: a standard output the shell closed (`>&-`), file names that
are not UTF-8 or not ASCII in every output that names them, and pictures of `rl1c sim`
that would replace its own inputs."""

import errno
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support import EXAMPLES, SAMPLE, SAMPLE_SENSORS
from support.cli import rl1c

from rl1.vm import ilc

RL1C = str(Path(sys.executable).with_name("rl1c"))
SAMPLE_WORLD = EXAMPLES / "sample.world.toml"
CLOSED = ("rl1c: error: cannot write the output: standard output is closed; send it to a "
          "file, a pipe or /dev/null (`> FILE`, not `>&-`)")


def _with_standard_output_closed(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([RL1C, *map(str, args)], stdin=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True, check=False,
                          preexec_fn=lambda: os.close(1))


@pytest.mark.parametrize(("command", "said"), [
    (["check", "-"], "error[E0100]: cannot read the source file `<stdin>`: standard input is "
                     "closed"),
    (["dis", "-"], "error[E0100]: cannot read the intermediate code file `<stdin>`: standard "
                   "input is closed"),
    (["run", "--batch"], "rl1c run: error: cannot read the jobs: standard input is closed; "
                         "send them through a pipe"),
])
def test_a_closed_standard_input_is_said_with_status_2_not_read_as_empty(
        command: list[str], said: str) -> None:
    done = subprocess.run([RL1C, *command], capture_output=True, text=True, check=False,
                          preexec_fn=lambda: os.close(0))
    assert done.returncode == 2, done.stderr
    said_all = done.stdout + done.stderr  # check reports on standard output
    assert said in said_all and "internal error" not in said_all


@pytest.mark.parametrize("command", [["check", str(SAMPLE)], ["dis", "{ilc}"], ["--help"]])
def test_a_closed_standard_output_is_said_in_one_line_with_status_2(
        command: list[str], tmp_path: Path) -> None:
    compiled = tmp_path / "sample.ilc"
    compiled.write_bytes(rl1c(SAMPLE, "-o", "-").stdout_bytes)
    done = _with_standard_output_closed(*(part.format(ilc=compiled) for part in command))
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines()[-1] == CLOSED


def test_a_closed_standard_output_leaves_a_compile_to_a_file_as_it_would_be(
        tmp_path: Path) -> None:
    # The output file must not take standard output's number and receive a report.
    target = tmp_path / "sample.ilc"
    assert rl1c(SAMPLE, "-o", target).exit_code == 0
    expected = target.read_bytes()
    target.unlink()
    done = _with_standard_output_closed(SAMPLE, "-o", target)
    assert done.returncode == 0, done.stderr
    assert target.read_bytes() == expected


@pytest.mark.parametrize("mode", ["wb", "ab"])  # `> x.ilc` empties it, `>> x.ilc` not
def test_an_input_that_standard_output_writes_is_refused_as_cat_refuses_it(
        mode: str, tmp_path: Path) -> None:
    compiled = tmp_path / "sample.ilc"
    compiled.write_bytes(rl1c(SAMPLE, "-o", "-").stdout_bytes)
    before = compiled.read_bytes() if mode == "ab" else b""
    with compiled.open(mode) as output:
        done = subprocess.run([RL1C, "dis", compiled], stdout=output, stderr=subprocess.PIPE,
                              text=True, check=False)
    assert done.returncode == 2
    assert (f"cannot read the intermediate code file `{compiled}`: it is where standard "
            "output goes too (the shell empties it for `> FILE` before rl1c runs)"
            ) in done.stderr
    assert compiled.read_bytes() == before  # no listing appended to the code


@pytest.fixture
def not_utf8(tmp_path: Path) -> Path:
    """A folder named with a byte that is not UTF-8, holding the sample program as
    `p\\xfe.rob` and its sensor script and world."""
    folder = tmp_path / os.fsdecode(b"d\xff")
    try:
        folder.mkdir()
    except (OSError, UnicodeEncodeError):  # a file system that takes only UTF-8 names
        pytest.skip("the file system refuses names that are not UTF-8")
    (folder / os.fsdecode(b"p\xfe.rob")).write_bytes(SAMPLE.read_bytes())
    return folder


def test_a_program_whose_name_is_not_utf8_compiles_and_runs(not_utf8: Path) -> None:
    program = not_utf8 / os.fsdecode(b"p\xfe.rob")
    compiled = not_utf8 / "p.ilc"
    assert rl1c(program, "-o", compiled).exit_code == 0
    listing = rl1c("dis", compiled)
    assert listing.exit_code == 0
    assert '.source "p\ufffd.rob"' in listing.stdout  # the byte as U+FFFD: UTF-8
    assert rl1c("run", program, "--sensors", SAMPLE_SENSORS).exit_code == 0
    text = rl1c(program, "--emit", "ils", "-o", "-")
    assert text.exit_code == 0
    assert text.stdout_bytes.decode("utf-8").startswith("; p\\udcfe.ilc:")


def test_a_simulation_of_a_program_whose_name_is_not_utf8_draws_its_pictures(
        not_utf8: Path) -> None:
    program = not_utf8 / os.fsdecode(b"p\xfe.rob")
    svg, page = not_utf8 / os.fsdecode(b"s\xfe.svg"), not_utf8 / "s.html"
    done = rl1c("sim", program, "--world", SAMPLE_WORLD, "--svg", svg, "--html", page)
    assert done.exit_code == 0, done.output
    assert "p\\udcfe.rob on sample.world.toml" in svg.read_text(encoding="utf-8")
    assert "p\\udcfe.rob on sample.world.toml" in page.read_text(encoding="utf-8")


def test_a_campaign_of_a_program_whose_name_is_not_utf8_draws_its_pictures(
        not_utf8: Path) -> None:
    """The single run's pictures escaped the name; a campaign's ended its runs in an
    internal error (UnicodeEncodeError) when it drew them."""
    program = not_utf8 / os.fsdecode(b"p\xfe.rob")
    svg, page = not_utf8 / "c.svg", not_utf8 / "c.html"
    done = rl1c("sim", program, "--world", SAMPLE_WORLD, "--runs", "2", "--svg", svg,
                "--html", page)
    assert done.exit_code == 0, done.output
    assert "p\\udcfe.rob on sample.world.toml: 2 runs" in svg.read_text(encoding="utf-8")
    assert "p\\udcfe.rob on sample.world.toml: 2 runs" in page.read_text(encoding="utf-8")


def test_sarif_gives_a_name_that_is_not_utf8_by_its_bytes(not_utf8: Path,
                                                         monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    monkeypatch.chdir(not_utf8.parent)
    (not_utf8 / os.fsdecode(b"e\xfe.rob")).write_text("A=1 B\n")
    named = os.path.join(not_utf8.name, os.fsdecode(b"e\xfe.rob"))
    done = rl1c("check", "--format", "sarif", named)
    assert done.exit_code == 1, done.output
    result, = json.loads(done.stdout)["runs"][0]["results"]
    assert result["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == \
        "d%FF/e%FE.rob"


def test_the_c_array_is_ascii_whatever_the_name_of_its_source(tmp_path: Path) -> None:
    program = tmp_path / "ロボ.rob"
    program.write_bytes(SAMPLE.read_bytes())
    done = rl1c(program, "--emit", "c", "-o", "-")
    assert done.exit_code == 0, done.output
    first = done.stdout_bytes.decode("ascii").splitlines()[0]
    assert first.startswith("/* The RL/I program \\xe3\\x83\\xad\\xe3\\x83\\x9c.rob as .ilc")


@pytest.mark.parametrize("option", ["--svg", "--html"])
@pytest.mark.parametrize("role", ["program", "world file"])
def test_a_picture_never_replaces_the_program_or_the_world(option: str, role: str,
                                                           tmp_path: Path) -> None:
    program, world = tmp_path / "sample.rob", tmp_path / "sample.world.toml"
    program.write_bytes(SAMPLE.read_bytes())
    world.write_bytes(SAMPLE_WORLD.read_bytes())
    target = program if role == "program" else world
    done = rl1c("sim", program, "--world", world, option, target)
    assert done.exit_code == 2
    assert f"{option} `{target}` is the {role} itself: give another path for the picture" \
        in done.stderr
    assert program.read_bytes() == SAMPLE.read_bytes()
    assert world.read_bytes() == SAMPLE_WORLD.read_bytes()


def test_a_byte_of_a_name_that_is_not_utf8_is_recorded_as_u_fffd() -> None:
    assert ilc.debug_source_name(os.fsdecode(b"d\xff/p\xfe.rob")) == "d\ufffd/p\ufffd.rob"


def test_the_two_pictures_of_a_run_are_never_one_file(tmp_path: Path) -> None:
    # The page replaced the top view without a word; a campaign refused it already.
    picture = tmp_path / "run.svg"
    done = rl1c("sim", SAMPLE, "--world", SAMPLE_WORLD, "--svg", picture, "--html", picture)
    assert done.exit_code == 2
    assert f"--html and --svg both name `{picture}`: give each its own file" in done.stderr
    assert not picture.exists()
    both = rl1c("sim", SAMPLE, "--world", SAMPLE_WORLD, "--svg", os.devnull, "--html",
                os.devnull)
    assert both.exit_code == 0, both.output


@given(st.text(st.characters(blacklist_categories=())))
def test_any_file_name_is_recorded_as_utf8_within_the_limit(name: str) -> None:
    recorded = ilc.debug_source_name(name)
    encoded = recorded.encode("utf-8")  # a surrogate left would raise here
    assert len(encoded) <= ilc.MAX_NAME_SIZE
    if not any("\ud800" <= character <= "\udfff" for character in name):
        assert name.endswith(recorded)
        whole = len(name.encode("utf-8"))
        assert len(encoded) == whole or len(encoded) > ilc.MAX_NAME_SIZE - 4


@pytest.mark.parametrize(("number", "help"), [
    (errno.ENOSPC, "free some space on its disk, or write elsewhere"),
    (errno.EROFS, "its file system is read-only: write elsewhere"),
])
def test_a_full_or_read_only_disk_is_said_with_what_to_do_about_it(
        number: int, help: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Checking the folder's permissions, as the help said, would change nothing.
    def failing_replace(source: str, destination: object) -> None:
        raise OSError(number, os.strerror(number))

    target = tmp_path / "sample.ilc"
    target.write_bytes(b"earlier")
    monkeypatch.setattr(os, "replace", failing_replace)
    done = rl1c(SAMPLE, "-o", target)
    assert done.exit_code == 2
    assert f"= help: {help}" in done.stderr
    assert target.read_bytes() == b"earlier"
