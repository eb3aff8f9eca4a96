"""Commands other packages add to rl1c through the entry points of `rl1.commands`
(compiler/cli/plugins.py): rl1.lsp's `rl1c studio` as installed, and plugins of a
distribution made for each test (a `.dist-info` folder on PYTHONPATH), working or broken,
run as a user runs rl1c, in a process of its own."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from importlib.metadata import entry_points
from pathlib import Path

import pytest
from support import ROOT, SAMPLE

from rl1.compiler.cli import main, plugins

RL1C = [sys.executable, "-c", "from rl1.compiler.cli.main import rl1c; rl1c()"]

# A plugin module with a command of its own, `rl1c hello`.
HELLO = '''
import click

from rl1.compiler.cli.command import Command

SECTION = "Greetings"


@click.command(cls=Command)
@click.argument("who")
def hello(who: str) -> int:
    """Say hello."""
    click.echo(f"hello, {who}")
    return 0


COMMANDS = (hello,)
'''


def distribution(folder: Path, plugins_: dict[str, str], modules: dict[str, str]) -> Path:
    """A distribution `fake-plugins` installed in `folder` (put on PYTHONPATH): its
    entry points `plugins_` (name to value) in the group, and the modules `modules`
    (name to source)."""
    info = folder / "fake_plugins-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: fake-plugins\n"
                                   "Version: 1.0\n")
    (info / "entry_points.txt").write_text(
        f"[{plugins.GROUP}]\n" + "".join(f"{name} = {value}\n"
                                         for name, value in plugins_.items()))
    for name, source in modules.items():
        (folder / f"{name}.py").write_text(source)
    return folder


def run(folder: Path, *args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """`rl1c ARGS` with the distribution of `folder` installed."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(folder), *filter(None, [os.environ.get("PYTHONPATH")])])}
    return subprocess.run([*RL1C, *args], capture_output=True, text=True, env=env, cwd=cwd,
                          timeout=60, check=False)


def test_rl1_adds_studio_through_the_entry_point_pyproject_toml_declares() -> None:
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())[
        "project"]["entry-points"][plugins.GROUP]
    installed = {entry.name: entry.value for entry in entry_points(group=plugins.GROUP)
                 if entry.dist is not None and entry.dist.name == "rl1"}
    assert installed == declared, (
        "the installed rl1's entry points are not pyproject.toml's: install it again "
        "(pip install -e . --no-deps)")
    studio = plugins.load("studio")
    assert (studio.section, studio.command.name) == ("Studio", "studio")
    assert "studio" in main.plugin_names() and "studio" not in main.COMMAND_NAMES


def test_rl1c_studio_help_is_the_studios() -> None:
    shown = subprocess.run([*RL1C, "studio", "--help"], capture_output=True, text=True,
                           timeout=60, check=False)
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout.startswith("usage: rl1c studio [OPTIONS] [FILE.rob]\n")
    assert "--no-browser" in shown.stdout


def test_a_plugin_runs_is_listed_in_its_section_and_completes(tmp_path: Path) -> None:
    folder = distribution(tmp_path, {"hello": "hello_plugin"}, {"hello_plugin": HELLO})
    ran = run(folder, "hello", "world")
    assert (ran.returncode, ran.stdout, ran.stderr) == (0, "hello, world\n", "")
    shown = run(folder, "--help")
    assert shown.returncode == 0
    assert "  Greetings:\n    hello  Say hello.\n" in shown.stdout
    assert "  Studio:\n    studio" in shown.stdout  # rl1's own plugin, beside it
    env = {**os.environ, "_RL1C_COMPLETE": "bash_complete", "COMP_WORDS": "rl1c he",
           "COMP_CWORD": "1", "PYTHONPATH": str(folder)}
    completed = subprocess.run([*RL1C], capture_output=True, text=True, env=env, timeout=60,
                               check=False)
    assert "plain,hello" in completed.stdout.splitlines()


def test_a_plugin_named_as_a_command_of_rl1c_does_not_replace_it(tmp_path: Path) -> None:
    folder = distribution(tmp_path, {"check": "check_plugin"},
                          {"check_plugin": HELLO.replace('"hello"', '"check"')
                           .replace("def hello", "def check").replace("(hello,)", "(check,)")})
    ran = run(folder, "check", str(SAMPLE))
    assert ran.returncode == 0, ran.stderr
    assert "hello" not in ran.stdout
    assert "Greetings" not in run(folder, "--help").stdout


def test_a_bare_word_names_a_plugin_before_a_file_of_that_name(tmp_path: Path) -> None:
    folder = distribution(tmp_path / "site", {"hello": "hello_plugin"},
                          {"hello_plugin": HELLO})
    (tmp_path / "hello").write_text("(END)\n")
    ran = run(folder, "hello", "there", cwd=tmp_path)
    assert (ran.returncode, ran.stdout) == (0, "hello, there\n")


BROKEN = {
    # The module is not installed.
    "gone": ("gone_plugin", {},
             "importing `gone_plugin` failed (ModuleNotFoundError: No module named "
             "'gone_plugin')"),
    # Importing it fails.
    "failing": ("failing_plugin", {"failing_plugin": "raise RuntimeError('half installed')\n"},
                "importing `failing_plugin` failed (RuntimeError: half installed)"),
    # An attribute, not a module.
    "attribute": ("hello_plugin:hello", {"hello_plugin": HELLO},
                  "`hello_plugin:hello` is not a module (name a module, without `:`)"),
    # No SECTION and COMMANDS.
    "bare": ("bare_plugin", {"bare_plugin": "X = 1\n"},
             "`bare_plugin` has no SECTION (a string) and COMMANDS (a tuple of click "
             "commands)"),
    # The module has no command of the entry point's name.
    "other": ("hello_plugin", {"hello_plugin": HELLO},
              "`hello_plugin` has no command named `other` in its COMMANDS"),
}


@pytest.mark.parametrize("name", sorted(BROKEN))
@pytest.mark.parametrize("args", [[], ["--help"], ["x.rob", "--no-such-option"]])
def test_a_plugin_that_cannot_be_loaded_says_why_and_what_to_do(
        tmp_path: Path, name: str, args: list[str]) -> None:
    value, modules, why = BROKEN[name]
    folder = distribution(tmp_path, {name: value}, modules)
    ran = run(folder, name, *args)
    assert ran.returncode == 2
    assert ran.stdout == ""
    assert ran.stderr == (
        f"rl1c {name}: error: the command cannot be loaded: {why}\n"
        f"  = help: `rl1c {name}` comes from fake-plugins (its entry point `{name} = "
        f"{value}` in the group `rl1.commands`); install it again, such as with `pip "
        "install --force-reinstall fake-plugins`, or `pip install -e .` in its "
        "checkout\n")


def test_help_lists_the_plugins_that_cannot_be_loaded_apart(tmp_path: Path) -> None:
    folder = distribution(tmp_path, {"gone": "gone_plugin", "hello": "hello_plugin"},
                          {"hello_plugin": HELLO})
    shown = run(folder, "--help")
    assert shown.returncode == 0, shown.stderr
    assert "Traceback" not in shown.stderr
    listed = " ".join(shown.stdout.split())
    assert ("Commands that cannot be loaded: gone Cannot be loaded: importing "
            "`gone_plugin` failed (ModuleNotFoundError: No module named 'gone_plugin')"
            ) in listed
    assert "Greetings: hello Say hello." in listed


def test_a_mistyped_command_is_matched_against_the_plugins_too(tmp_path: Path) -> None:
    folder = distribution(tmp_path, {"hello": "hello_plugin"}, {"hello_plugin": HELLO})
    ran = run(folder, "helo")
    assert ran.returncode == 2
    assert ran.stderr.endswith("rl1c: error: No such command 'helo'. Did you mean "
                               "'hello'?\n")


@pytest.mark.parametrize("broken", [b"[rl1.commands]\nno equals sign\n",
                                    b"\xff\xfe[rl1.commands]\n"])
def test_a_package_whose_entry_points_cannot_be_read_is_left_out_with_a_warning(
        tmp_path: Path, broken: bytes) -> None:
    folder = distribution(tmp_path, {"hello": "hello_plugin"}, {"hello_plugin": HELLO})
    other = tmp_path / "other-1.0.dist-info"
    other.mkdir()
    (other / "METADATA").write_text("Metadata-Version: 2.1\nName: other\nVersion: 1.0\n")
    (other / "entry_points.txt").write_bytes(broken)
    warning = (f"rl1c: warning: cannot read the entry points (entry_points.txt) of the "
               f"package `other` in {tmp_path} (")
    for args, shown in ((["hello", "world"], "hello, world\n"), (["--help"], "Greetings:")):
        ran = run(folder, *args)
        assert ran.returncode == 0, ran.stderr
        assert shown in ran.stdout
        assert ran.stderr.startswith(warning) and ran.stderr.endswith(
            "which may add commands to rl1c; they are left out: install that package "
            "again\n")
        assert ran.stderr.count("\n") == 1
