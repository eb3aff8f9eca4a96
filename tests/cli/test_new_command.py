"""`rl1c new DIR`: the project it starts works as written (its tests pass, `rl1c check`
and `rl1c sim` accept it, the editor files are what VS Code reads), it never writes
into a folder that holds anything, and a failure leaves nothing behind."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pytest
from support.cli import rl1c

from rl1.compiler.cli.project_template import FILES


def jsonc(text: str) -> object:
    """The data of a JSON-with-comments file as VS Code reads tasks.json and launch.json
    (whole-line comments only, which is all the templates write)."""
    return json.loads(re.sub(r"(?m)^\s*//.*$", "", text))


def created(tmp_path: Path) -> Path:
    folder = tmp_path / "robot"
    result = rl1c("new", folder)
    assert result.exit_code == 0, result.output
    assert f"created {folder}: " in result.stdout
    return folder


def test_it_writes_the_projects_files(tmp_path: Path) -> None:
    folder = created(tmp_path)
    written = sorted(str(path.relative_to(folder)) for path in folder.rglob("*")
                     if path.is_file())
    assert written == sorted(FILES)
    for name, text in FILES.items():
        assert (folder / name).read_text(encoding="utf-8") == text
    mode = os.stat(folder).st_mode & 0o777
    umask = os.umask(0)
    os.umask(umask)
    assert mode == 0o777 & ~umask  # as mkdir makes a folder, not the temporary one's 0700
    assert [path.name for path in tmp_path.iterdir()] == ["robot"]  # no temporary left


def test_its_tests_pass_as_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = created(tmp_path)
    monkeypatch.chdir(folder)
    result = rl1c("test", "--jobs", "1")
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[0] == "main.tests.toml ..."


def test_check_and_sim_accept_it(tmp_path: Path) -> None:
    folder = created(tmp_path)
    checked = rl1c("check", folder)  # with its rl1.toml: warnings are errors
    assert checked.exit_code == 0, checked.output
    assert "1 file checked: 0 errors, 0 warnings" in checked.stdout
    simulated = rl1c("sim", folder / "main.rob", "--world", folder / "main.world.toml")
    assert simulated.exit_code == 0, simulated.output
    assert "goal met" in simulated.stdout
    ran = rl1c("run", folder / "main.rob", "--sensors", folder / "main.sensors.toml")
    assert ran.exit_code == 0, ran.output


def test_the_editor_files_run_rl1c_and_debug_at_level_0(tmp_path: Path) -> None:
    folder = created(tmp_path)
    tasks = jsonc((folder / ".vscode" / "tasks.json").read_text())
    assert isinstance(tasks, dict)
    commands = [(task["command"], task["args"][0]) for task in tasks["tasks"]]
    assert commands == [("rl1c", "check"), ("rl1c", "test"), ("rl1c", "sim")]
    assert tasks["tasks"][0]["problemMatcher"] == ["$rl1c"]
    assert tasks["tasks"][0]["args"][:3] == ["check", "--format", "concise"]
    launch = jsonc((folder / ".vscode" / "launch.json").read_text())
    assert isinstance(launch, dict)
    configurations = launch["configurations"]
    assert {(c["type"], c["request"], c["level"]) for c in configurations} == {
        ("rl1", "launch", 0)}
    for configuration in configurations:
        for key in ("program", "world", "sensors"):
            if key in configuration:
                path = configuration[key].replace("${workspaceFolder}", str(folder))
                assert Path(path).is_file()


def test_every_file_says_what_it_is(tmp_path: Path) -> None:
    for name, text in FILES.items():
        comment = "'" if name.endswith(".rob") else "//" if name.endswith(".json") else "#"
        assert text.startswith(comment), name


def test_an_empty_folder_is_used_and_kept(tmp_path: Path,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "empty"
    folder.mkdir()
    inode = folder.stat().st_ino
    monkeypatch.chdir(folder)
    result = rl1c("new", ".")
    assert result.exit_code == 0, result.output
    # The same folder, not one renamed over it: a shell in it sees the files.
    assert folder.stat().st_ino == inode
    assert sorted(os.listdir(".")) == sorted({name.split("/")[0] for name in FILES})
    assert "next: rl1c test" in result.stdout
    assert [path.name for path in tmp_path.iterdir()] == ["empty"]  # no temporary left


def test_a_failure_moving_into_an_empty_folder_leaves_it_empty(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "empty"
    folder.mkdir()
    rename = os.rename
    calls = []

    def third_fails(source: str, target: str) -> None:
        calls.append(target)
        if len(calls) == 3:
            raise OSError(28, "No space left on device")
        rename(source, target)

    monkeypatch.setattr(os, "rename", third_fails)
    result = rl1c("new", folder)
    assert result.exit_code == 2
    assert "no space left on device" in result.stderr
    assert list(folder.iterdir()) == []
    assert [path.name for path in tmp_path.iterdir()] == ["empty"]


def test_a_folder_that_holds_anything_is_refused_and_left_alone(tmp_path: Path) -> None:
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / ".keep").write_text("mine")
    result = rl1c("new", folder)
    assert result.exit_code == 2
    assert f"`{folder}` is not empty (it holds `.keep`)" in result.stderr
    assert "give another path" in result.stderr
    assert [path.name for path in folder.iterdir()] == [".keep"]
    assert [path.name for path in tmp_path.iterdir()] == ["mine"]


def test_a_file_in_the_way_is_refused(tmp_path: Path) -> None:
    file = tmp_path / "robot"
    file.write_text("mine")
    result = rl1c("new", file)
    assert result.exit_code == 2
    assert "exists and is no folder" in result.stderr
    assert file.read_text() == "mine"


def test_a_missing_parent_folder_is_said(tmp_path: Path) -> None:
    result = rl1c("new", tmp_path / "no" / "robot")
    assert result.exit_code == 2
    assert "cannot create the project folder" in result.stderr
    assert "no such file or directory" in result.stderr
    assert "Traceback" not in result.output


def test_a_failure_on_the_way_leaves_nothing(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(source: str, target: str) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "rename", refuse)
    result = rl1c("new", tmp_path / "robot")
    assert result.exit_code == 2
    assert "cannot create the project folder" in result.stderr
    assert "no space left on device" in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("empty_folder", "interrupted_at"),
                         [(False, 1), (True, 1), (True, 2), (True, 4)])
def test_ctrl_c_on_the_way_leaves_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                          interrupted_at: int, empty_folder: bool) -> None:
    # Only an OSError was cleaned up: Ctrl-C left a hidden `.robot.XXXX.tmp` beside DIR,
    # or, moving into an empty DIR, the files moved so far.
    folder = tmp_path / "robot"
    if empty_folder:
        folder.mkdir()
    rename = os.rename
    calls = []

    def interrupted(source: str, target: str) -> None:
        calls.append(target)
        if len(calls) == interrupted_at:
            raise KeyboardInterrupt
        rename(source, target)

    monkeypatch.setattr(os, "rename", interrupted)
    result = rl1c("new", folder)
    assert result.exit_code == 130
    assert [path.name for path in tmp_path.iterdir()] == (["robot"] if empty_folder else [])
    assert not empty_folder or list(folder.iterdir()) == []
