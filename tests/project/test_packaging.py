"""What a normal (non-editable) install contains: every package folder and data file.

An editable install maps whole folders, so a package missing from pyproject.toml only
shows up in a wheel; these checks catch that without building one."""

import tomllib
from pathlib import Path

from support import ROOT

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
