"""The `rl1c` command line itself: a first word that is no command is a file to compile
or a mistyped command, and shell completion of commands, options, files and codes."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from click.shell_completion import ShellComplete
from click.testing import CliRunner
from support import SAMPLE
from support.cli import rl1c

from rl1.compiler.cli.main import rl1c as command
from rl1.compiler.reporting.catalogue import CODES
from rl1.vm.verifier import verify

# A mistyped command ----------------------------------------------------------------------


@pytest.mark.parametrize("args", [["chek", "x.rob"], ["chek"], ["Check", "x.rob"]])
def test_a_mistyped_command_gets_a_suggestion(args: list[str]) -> None:
    result = rl1c(*args)
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr.startswith("usage: rl1c")
    assert f"rl1c: error: No such command '{args[0]}'. Did you mean 'check'?\n" in result.stderr


def test_an_unknown_word_lists_the_commands_and_how_to_compile() -> None:
    result = rl1c("frobnicate")
    assert result.exit_code == 2
    assert "No such command 'frobnicate'." in result.stderr
    assert "check, fmt, explain, compile, run, dis, asm" in result.stderr
    assert "rl1c prog.rob" in result.stderr


@pytest.mark.parametrize("name", ["chek.rob", "chek.txt", "sub/chek", "./chek"])
def test_a_word_with_an_extension_or_a_directory_is_a_file_to_compile(
    name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(tmp_path)
    missing = rl1c(name)
    assert missing.exit_code == 2
    assert "error[E0100]" in missing.stderr and "No such command" not in missing.stderr
    Path(name).parent.mkdir(exist_ok=True)
    shutil.copy(SAMPLE, name)
    assert rl1c(name, "-o", "out.ilc").exit_code == 0
    verify(Path("out.ilc").read_bytes())


def test_an_existing_file_is_compiled_even_when_it_looks_like_a_command(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(tmp_path)
    shutil.copy(SAMPLE, "chek")
    result = rl1c("chek")
    assert result.exit_code == 0, result.stderr
    verify(Path("chek.ilc").read_bytes())


# Shell completion --------------------------------------------------------------------------


def completions(args: list[str], incomplete: str) -> list[tuple[str, str]]:
    """What the shell is offered for `rl1c ARGS INCOMPLETE<TAB>`: (value, type) pairs,
    "file" asking the shell for file names."""
    complete = ShellComplete(command, {}, "rl1c", "_RL1C_COMPLETE")
    return [(item.value, item.type) for item in complete.get_completions(args, incomplete)]


def test_command_names_complete_with_file_names() -> None:
    assert completions([], "ch") == [("check", "plain"), ("ch", "file")]
    names = [value for value, kind in completions([], "") if kind == "plain"]
    assert names == sorted(["check", "fmt", "explain", "compile", "run", "dis", "asm", "sim",
                            "test", "new", "studio", "fuzz", "reduce", "docs"])


def test_options_and_their_choices_complete() -> None:
    assert completions(["check"], "--fo") == [("--format", "plain"), ("--force", "plain")]
    assert completions(["check", "--format"], "") == [
        ("human", "plain"), ("concise", "plain"), ("json", "plain"), ("sarif", "plain")]
    assert completions(["run", "x.rob", "--engine"], "a") == [("ast", "plain")]
    # `rl1c FILE.rob` is `rl1c compile FILE.rob`: its options complete too.
    assert ("--emit", "plain") in completions(["prog.rob"], "--")


@pytest.mark.parametrize("args", [["check"], ["check", "a.rob"], ["run", "x.rob", "--sensors"],
                                  ["compile", "x.rob", "-o"], ["dis"]])
def test_file_arguments_and_options_complete_file_names(args: list[str]) -> None:
    assert completions(args, "exa") == [("exa", "file")]


@pytest.mark.parametrize("typed", ["W03", "w03", ""])
def test_explain_completes_the_diagnostic_codes(typed: str) -> None:
    expected = [code for code in CODES if code.startswith(typed.upper())]
    assert expected
    assert completions(["explain"], typed) == [(code, "plain") for code in expected]


@pytest.mark.parametrize("words", ["rl1c \udcff", "rl1c check a\udcff",
                                   "rl1c run x.rob --sensors \udcff"])
def test_a_word_that_is_not_utf8_completes_to_nothing_not_an_internal_error(
        words: str) -> None:
    # Bytes of a Latin-1 file name, which click failed to write back as UTF-8.
    completing = subprocess.run(
        [str(Path(sys.executable).with_name("rl1c"))], capture_output=True, check=False,
        env={**os.environ, "_RL1C_COMPLETE": "bash_complete", "COMP_WORDS": words,
             "COMP_CWORD": str(len(words.split(" ")) - 1)})
    assert (completing.returncode, completing.stdout, completing.stderr) == (0, b"\n", b"")


def test_completion_through_the_environment_the_shell_sets() -> None:
    result = CliRunner().invoke(command, env={
        "_RL1C_COMPLETE": "bash_complete", "COMP_WORDS": "rl1c explain W030",
        "COMP_CWORD": "2"})
    assert result.exit_code == 0
    codes = [code for code in CODES if code.startswith("W030")]
    assert result.stdout.splitlines() == [f"plain,{code}" for code in codes]


@pytest.mark.parametrize("shell", ["bash", "zsh", "fish"])
def test_each_shell_gets_its_completion_script(shell: str) -> None:
    if shell == "bash" and shutil.which("bash") is None:
        pytest.skip("click checks the version of bash before writing its script")
    result = CliRunner().invoke(command, env={"_RL1C_COMPLETE": f"{shell}_source"})
    assert result.exit_code == 0
    assert "_RL1C_COMPLETE" in result.stdout and f"{shell}_complete" in result.stdout
