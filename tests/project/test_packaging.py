"""What a normal (non-editable) install contains: every package folder and data file.

An editable install maps whole folders, so a package missing from pyproject.toml only
shows up in a wheel; these checks catch that without building one."""

import zipfile
from pathlib import Path

import pytest
from support import ROOT
from support.wheel import SETUPTOOLS, built_wheel

from rl1.compiler.cli import docs
from rl1.vm import native


def _package_of(folder: Path) -> str:
    top, *rest = folder.relative_to(ROOT).parts
    mapped = {path: name for name, path in SETUPTOOLS["package-dir"].items()}
    return ".".join([mapped[top], *rest])


def test_every_package_folder_is_listed() -> None:
    folders = {init.parent for top in SETUPTOOLS["package-dir"].values()
               for init in (ROOT / top).rglob("__init__.py")}
    code_packages = {_package_of(folder) for folder in folders}
    listed = set(SETUPTOOLS["packages"])
    assert code_packages <= listed
    # A folder of data only is listed as a package of its own, so that setuptools neither
    # warns that it "would be ignored" nor leaves it out of the wheel.
    assert all(package in SETUPTOOLS["package-data"] for package in listed - code_packages)


def test_data_files_the_code_reads_are_package_data() -> None:
    assert "*.lark" in SETUPTOOLS["package-data"]["rl1.compiler.frontend"]
    assert "*.md" in SETUPTOOLS["package-data"]["rl1.compiler.reporting.explanations"]
    assert list((ROOT / "compiler" / "reporting" / "explanations").glob("*.md"))


@pytest.mark.slow  # a wheel build: seconds
def test_a_wheel_builds_without_warnings_and_holds_the_data(
        tmp_path_factory: pytest.TempPathFactory) -> None:
    """`pip install .` builds this wheel: setuptools warns of a data folder that is not
    a listed package ("would be ignored"), and a missing data file breaks `rl1c explain`,
    `rl1c run --engine c` or `rl1c docs`."""
    built = built_wheel(tmp_path_factory)
    assert built.status == 0 and built.wheel is not None, built.said
    assert "warning" not in built.said.lower()
    names = set(zipfile.ZipFile(built.wheel).namelist())
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
