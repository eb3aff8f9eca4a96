"""The wheel `pip wheel .` builds from a copy of the checkout's packaged files, built once
a test run: tests/project/test_packaging.py reads its content and what pip said, and
test_wheel.py installs it. Under pytest-xdist the first worker to ask builds it in the
folder the workers share, and the others wait for it (a lock) and take it."""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

from support import ROOT

SETUPTOOLS = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))[
    "tool"]["setuptools"]


@dataclass(frozen=True)
class Built:
    """What `pip wheel` made: its status, what it printed, and the wheel (None when it
    failed)."""

    status: int
    said: str
    wheel: Path | None


def built_wheel(tmp_path_factory: pytest.TempPathFactory) -> Built:
    """The wheel of this test run, built on the first call."""
    shared = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        shared = shared.parent  # the run's folder, above each worker's own
    folder = shared / "wheel"
    with open(shared / "wheel.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when closed
        if not (folder / "built.json").exists():
            _build(folder)
    told = json.loads((folder / "built.json").read_text(encoding="utf-8"))
    wheels = list((folder / "dist").glob("rl1-*.whl"))
    assert len(wheels) <= 1, wheels
    return Built(told["status"], told["said"], wheels[0] if wheels else None)


def _build(folder: Path) -> None:
    """Build the wheel in `folder`/dist and write built.json (pip's status and output)
    last, so that a build cut short is not taken for one done."""
    shutil.rmtree(folder, ignore_errors=True)  # what a worker that died left
    source = folder / "source"
    source.mkdir(parents=True)
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(ROOT / name, source / name)
    for top in SETUPTOOLS["package-dir"].values():  # not the C VM's build outputs
        shutil.copytree(ROOT / top, source / top,
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "build"))
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", ".", "--no-deps", "--quiet",
                           "-w", str(folder / "dist")], cwd=source, capture_output=True,
                          text=True, check=False)
    (folder / "built.json").write_text(
        json.dumps({"status": done.returncode, "said": done.stdout + done.stderr}),
        encoding="utf-8")
