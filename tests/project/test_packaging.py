"""What a normal (non-editable) install contains: every package folder and data file.

An editable install maps whole folders, so a package missing from pyproject.toml only
shows up in a wheel; these checks catch that without building one."""

import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest
from support import ROOT

from rl1.compiler.cli import docs
from rl1.vm import native

CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]


def _package_of(folder: Path) -> str:
    top, *rest = folder.relative_to(ROOT).parts
    mapped = {path: name for name, path in CONFIG["package-dir"].items()}
    return ".".join([mapped[top], *rest])


def test_every_package_folder_is_listed() -> None:
    folders = {init.parent for top in CONFIG["package-dir"].values()
               for init in (ROOT / top).rglob("__init__.py")}
    code_packages = {_package_of(folder) for folder in folders}
    listed = set(CONFIG["packages"])
    assert code_packages <= listed
    # A folder of data only is listed as a package of its own, so that setuptools neither
    # warns that it "would be ignored" nor leaves it out of the wheel.
    assert all(package in CONFIG["package-data"] for package in listed - code_packages)


def test_data_files_the_code_reads_are_package_data() -> None:
    assert "*.lark" in CONFIG["package-data"]["rl1.compiler.frontend"]
    assert "*.md" in CONFIG["package-data"]["rl1.compiler.reporting.explanations"]
    assert list((ROOT / "compiler" / "reporting" / "explanations").glob("*.md"))


@pytest.mark.slow  # a wheel build: seconds
def test_a_wheel_builds_without_warnings_and_holds_the_data(tmp_path: Path) -> None:
    """`pip install .` builds this wheel: setuptools warns of a data folder that is not
    a listed package ("would be ignored"), and a missing data file breaks `rl1c explain`,
    `rl1c run --engine c` or `rl1c docs`."""
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(ROOT / name, tmp_path / name)
    for top in CONFIG["package-dir"].values():
        shutil.copytree(ROOT / top, tmp_path / top,
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", ".", "--no-deps",
                            "--quiet", "-w", "dist"],
                           cwd=tmp_path, capture_output=True, text=True, check=False)
    assert built.returncode == 0, built.stderr
    assert "warning" not in (built.stdout + built.stderr).lower()
    (wheel,) = (tmp_path / "dist").glob("rl1-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    explanations = {f"rl1/compiler/reporting/explanations/{md.name}"
                    for md in (ROOT / "compiler" / "reporting" / "explanations").glob("*.md")}
    assert explanations <= names
    assert "rl1/compiler/frontend/grammar.lark" in names
    assert "rl1/compiler/frontend/lalr_tables.py" in names
    # What `rl1c run --engine c` builds the C VM from, where vm/native.py looks for it.
    for path in (*native.SOURCES, *native.HEADERS):
        assert f"rl1/{path.relative_to(ROOT).as_posix()}" in names, path
    # What `rl1c docs` prints.
    for path in docs.documents().values():
        assert f"rl1/{path.relative_to(ROOT).as_posix()}" in names, path
