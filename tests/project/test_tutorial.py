"""docs/tutorial.md shows what really happens: in an empty folder, in the order a reader
meets them, its files are written (each code block after a `<!-- file: NAME -->`
comment; after `<!-- append: NAME -->`, added to the end of that file) and its sessions
run (a code block of `$ rl1c ...` lines, each followed by what it printed); a line `...`
in a printed output stands for any lines, and a campaign's progress lines, which depend
on its speed, are left out."""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

import pytest
from support import ROOT
from support.cli import rl1c

TUTORIAL = ROOT / "docs" / "tutorial.md"
BLOCK = re.compile(r"^(?:<!-- (?P<how>file|append): (?P<file>\S+) -->\n)?```\w*\n"
                   r"(?P<body>.*?)^```", re.MULTILINE | re.DOTALL)
# What `rl1c sim --runs` prints on standard error every few seconds when not on a terminal.
PROGRESS = re.compile(r"^\d+/\d+ runs, \d+ succeeded \(.*\), [\d.]+ runs/s$")


@dataclass(frozen=True)
class Write:
    """A file of the tutorial: written whole, or (`append`) added to its end."""

    name: str
    text: str
    append: bool


@dataclass(frozen=True)
class Session:
    """A `$ ` command of the tutorial with the lines it printed."""

    command: str
    printed: list[str]


def steps(markdown: str) -> list[Write | Session]:
    """The files and the commands of `markdown`, in the order they come."""
    found: list[Write | Session] = []
    for block in BLOCK.finditer(markdown):
        if block["file"]:
            found.append(Write(block["file"], block["body"], block["how"] == "append"))
        elif block["body"].startswith("$ "):
            for part in re.split(r"^\$ ", block["body"], flags=re.MULTILINE)[1:]:
                command, *printed = part.rstrip("\n").split("\n")
                found.append(Session(command, printed))
    return found


def tutorial_steps() -> list[Write | Session]:
    return steps(TUTORIAL.read_text(encoding="utf-8"))


def files() -> set[str]:
    return {step.name for step in tutorial_steps() if isinstance(step, Write)}


def sessions() -> list[Session]:
    return [step for step in tutorial_steps() if isinstance(step, Session)]


def matches(printed: list[str], expected: list[str]) -> bool:
    """Whether `printed` is `expected`, where a line `...` stands for any lines."""
    if not expected:
        return not printed
    if expected[0] == "...":
        return any(matches(printed[skip:], expected[1:]) for skip in range(len(printed) + 1))
    return bool(printed) and printed[0] == expected[0] and matches(printed[1:], expected[1:])


def test_dots_stand_for_any_lines() -> None:
    assert matches(["a", "b", "c", "d"], ["a", "...", "d"])
    assert matches(["a", "d"], ["a", "...", "d"])
    assert not matches(["a", "b"], ["a", "...", "d"])
    assert not matches(["a", "x"], ["a", "b"])


def test_files_and_sessions_come_in_the_order_written() -> None:
    markdown = ("<!-- file: a.toml -->\n```toml\nx = 1\n```\n"
                "```\n$ rl1c run a\nran\n$ rl1c sim a\n```\n"
                "<!-- append: a.toml -->\n```toml\ny = 2\n```\n"
                "```sh\nrl1c studio  # not a session: no `$ `\n```\n")
    assert steps(markdown) == [Write("a.toml", "x = 1\n", False),
                               Session("rl1c run a", ["ran"]), Session("rl1c sim a", []),
                               Write("a.toml", "y = 2\n", True)]


def test_the_tutorial_has_its_files_and_its_sessions() -> None:
    assert {"first.rob", "first.sensors.toml", "first.world.toml", "oops.rob"} <= files()
    commands = [session.command for session in sessions()]
    for command in ("check", "run", "sim"):
        assert any(line.startswith(f"rl1c {command} first.rob") for line in commands), command
    assert any("--runs" in line for line in commands), "the tutorial asks how often"


@pytest.mark.slow  # a campaign of 100 runs among them: some 3 s, most of it the pool's
def test_each_command_prints_what_the_tutorial_shows(tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """In order, in one folder, as a reader would: `rl1c dis` reads what `rl1c` wrote,
    and the sessions after an appended block see the file with it."""
    monkeypatch.chdir(tmp_path)
    for step in tutorial_steps():
        if isinstance(step, Write):
            with (tmp_path / step.name).open("a" if step.append else "w",
                                             encoding="utf-8") as file:
                file.write(step.text)
            continue
        program, *args = shlex.split(step.command)
        assert program == "rl1c", step.command
        printed = [line for line in rl1c(*args).output.splitlines()
                   if not PROGRESS.match(line)]
        assert matches(printed, step.printed), (
            f"docs/tutorial.md shows for `{step.command}`:\n" + "\n".join(step.printed)
            + "\n\nbut it prints:\n" + "\n".join(printed))
