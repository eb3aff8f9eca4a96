"""The VS Code package is one bundled script and a few files: `npm run package` (tsc, then
esbuild, then vsce) makes editors/vscode/rl1.vsix with dist/extension.js, the grammar,
the language configuration, the README and the licence, and no node_modules; the bundle
needs nothing at run time but `vscode` and node's own modules. esbuild is installed
from package-lock.json, at the exact version package.json names."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest
from support import ROOT

VSCODE = ROOT / "editors" / "vscode"
PACKAGE = json.loads((VSCODE / "package.json").read_text(encoding="utf-8"))
# What the .vsix holds beside its own manifest files, under extension/.
SHIPPED = {"dist/extension.js", "syntaxes/rl1.tmLanguage.json", "language-configuration.json",
           "package.json", "readme.md", "LICENSE.txt"}


def test_esbuild_is_pinned_in_package_json_and_locked() -> None:
    pinned = PACKAGE["devDependencies"]["esbuild"]
    assert re.fullmatch(r"\d+\.\d+\.\d+", pinned), f"esbuild {pinned!r} is not an exact version"
    lock = json.loads((VSCODE / "package-lock.json").read_text(encoding="utf-8"))
    assert lock["packages"]["node_modules/esbuild"]["version"] == pinned
    assert PACKAGE["main"] == "./dist/extension.js"


@pytest.fixture(scope="module")
def vsix(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """rl1.vsix as `make vscode-package` builds it, in a copy of editors/vscode (the
    node_modules that `npm ci` installed for `make vscode-test`, linked)."""
    modules = VSCODE / "node_modules"
    if not (modules / ".bin" / "vsce").exists():
        pytest.skip("editors/vscode/node_modules is not installed: `make vscode-test` "
                    "installs it from package-lock.json")
    folder = tmp_path_factory.mktemp("vscode") / "vscode"
    shutil.copytree(VSCODE, folder, ignore=shutil.ignore_patterns(
        "node_modules", "out", "dist", "*.vsix"))
    (folder / "node_modules").symlink_to(modules)
    built = subprocess.run(["npm", "run", "--silent", "package"], cwd=folder,
                           capture_output=True, text=True, timeout=300, check=False)
    assert built.returncode == 0, built.stdout + built.stderr
    return folder / "rl1.vsix"


def _node_builtins() -> set[str]:
    listed = subprocess.run(["node", "-p", "JSON.stringify(require('module').builtinModules)"],
                            capture_output=True, text=True, check=True)
    return set(json.loads(listed.stdout))


@pytest.mark.slow  # npm runs tsc, esbuild and vsce
@pytest.mark.needs_node
def test_the_package_holds_the_bundle_and_few_files(vsix: Path) -> None:
    names = zipfile.ZipFile(vsix).namelist()
    content = {name.removeprefix("extension/") for name in names
               if name.startswith("extension/")}
    assert content == SHIPPED
    assert not [name for name in names if "node_modules" in name or "/out/" in name]


@pytest.mark.slow  # npm runs tsc, esbuild and vsce
@pytest.mark.needs_node
def test_the_bundle_needs_only_vscode_and_node(vsix: Path) -> None:
    with zipfile.ZipFile(vsix) as archive:
        bundle = archive.read("extension/dist/extension.js").decode("utf-8")
        manifest = json.loads(archive.read("extension/package.json"))
    assert manifest["main"] == "./dist/extension.js"
    required = set(re.findall(r"""\brequire\(["']([^"']+)["']\)""", bundle))
    assert "vscode" in required  # the scan sees the bundle's requires
    builtins = _node_builtins()
    outside = {name for name in required - {"vscode"}
               if name.removeprefix("node:") not in builtins}
    assert not outside, f"the bundle would load {outside} from node_modules, which is not shipped"
    # vscode-languageclient is inside the bundle.
    assert "LanguageClient" in bundle
