"""docs/tutorial.md shows what really happens: its files (each code block after a
`<!-- file: NAME -->` comment) are written to an empty folder, and each of its sessions
(a code block of `$ rl1c ...` lines, each followed by what it printed) is run there; a
line `...` in a printed output stands for any lines."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from support import ROOT
from support.cli import rl1c

TUTORIAL = ROOT / "docs" / "tutorial.md"
BLOCK = re.compile(r"^(?:<!-- file: (?P<file>\S+) -->\n)?```\w*\n(?P<body>.*?)^```",
                   re.MULTILINE | re.DOTALL)


def _blocks() -> list[re.Match[str]]:
    return list(BLOCK.finditer(TUTORIAL.read_text(encoding="utf-8")))


def files() -> dict[str, str]:
    return {block["file"]: block["body"] for block in _blocks() if block["file"]}


def sessions() -> list[tuple[str, list[str]]]:
    """Each `$ ` command of the tutorial with the lines it printed."""
    found: list[tuple[str, list[str]]] = []
    for block in _blocks():
        if not block["body"].startswith("$ "):
            continue
        for part in re.split(r"^\$ ", block["body"], flags=re.MULTILINE)[1:]:
            command, *printed = part.rstrip("\n").split("\n")
            found.append((command, printed))
    return found


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


def test_the_tutorial_has_its_files_and_its_sessions() -> None:
    assert {"first.rob", "first.sensors.toml", "first.world.toml", "oops.rob"} <= set(files())
    commands = [command for command, _ in sessions()]
    for command in ("check", "run", "sim"):
        assert any(line.startswith(f"rl1c {command} first.rob") for line in commands), command


def test_each_command_prints_what_the_tutorial_shows(tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """In order, in one folder, as a reader would: `rl1c dis` reads what `rl1c` wrote."""
    for name, text in files().items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    for command, expected in sessions():
        program, *args = shlex.split(command)
        assert program == "rl1c", command
        printed = rl1c(*args).output.splitlines()
        assert matches(printed, expected), (
            f"docs/tutorial.md shows for `{command}`:\n" + "\n".join(expected)
            + "\n\nbut it prints:\n" + "\n".join(printed))
