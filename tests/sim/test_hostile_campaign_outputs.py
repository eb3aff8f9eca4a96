"""A campaign's pictures onto hostile targets, each refused before any run: --svg and
--out naming one file (the JSON lines were replaced by the picture, the runs lost),
--svg and --html naming one file (the page replaced the picture), a folder, an empty
path or a path in a missing folder (found only after every run was made). A device such
as /dev/null may still take every output."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.cli import rl1c

from rl1.compiler.cli.project_template import FILES


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    for name in ("main.rob", "main.world.toml"):
        (tmp_path / name).write_text(FILES[name], encoding="utf-8")
    (tmp_path / "folder").mkdir()
    monkeypatch.chdir(tmp_path)
    return tmp_path


def campaign(*options: str) -> tuple[int, str, str]:
    result = rl1c("sim", "main.rob", "--world", "main.world.toml", "--runs", "2",
                  "--jobs", "1", *options)
    return result.exit_code, result.stdout, result.stderr


@pytest.mark.parametrize(("options", "said"), [
    (("--svg", "runs.txt", "--out", "runs.txt"), "--svg and --out both name `runs.txt`"),
    (("--html", "./runs.txt", "--out", "runs.txt"), "--html and --out both name"),
    (("--svg", "p.svg", "--html", "./p.svg"), "--html and --svg both name `./p.svg`"),
    (("--svg", "folder"), "--svg `folder` is a folder"),
    (("--svg", ""), "--svg `` is a folder"),  # the current one
    (("--html", "missing/p.html"), "--html `missing/p.html`: its folder does not exist"),
])
def test_a_picture_onto_a_hostile_target_is_refused_before_any_run(
        project: Path, options: tuple[str, ...], said: str) -> None:
    (project / "runs.txt").write_text("kept")
    status, out, err = campaign(*options)
    assert status == 2
    assert said in err
    assert out == ""  # no run was made
    assert (project / "runs.txt").read_text() == "kept"
    assert sorted(path.name for path in project.iterdir()) == [
        "folder", "main.rob", "main.world.toml", "runs.txt"]


def test_a_device_takes_every_output_of_a_campaign(project: Path) -> None:
    status, out, err = campaign("--svg", "/dev/null", "--html", "/dev/null",
                                "--out", "/dev/null")
    assert status == 0, err
    assert "2 runs of main.rob" in out
