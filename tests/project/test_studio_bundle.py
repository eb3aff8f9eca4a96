"""The studio's page is committed built (lsp/studio/static/), so that the wheel and a
`pipx install` need no Node.js: rebuilding it from editors/studio's sources with the
esbuild of its lock file gives the same bytes (esbuild's output is deterministic), so
what is committed is what the sources say. esbuild is pinned to an exact version."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from support import ROOT

STUDIO = ROOT / "editors" / "studio"
STATIC = ROOT / "lsp" / "studio" / "static"
BUILT = ("index.html", "studio.js", "studio.css")


def test_esbuild_is_pinned_in_package_json_and_locked() -> None:
    package = json.loads((STUDIO / "package.json").read_text(encoding="utf-8"))
    pinned = package["devDependencies"]["esbuild"]
    assert re.fullmatch(r"\d+\.\d+\.\d+", pinned), f"esbuild {pinned!r} is not an exact version"
    lock = json.loads((STUDIO / "package-lock.json").read_text(encoding="utf-8"))
    assert lock["packages"]["node_modules/esbuild"]["version"] == pinned


def test_the_page_names_its_files_with_the_token() -> None:
    page = (STATIC / "index.html").read_text(encoding="utf-8")
    named = re.findall(r'(?:src|href)="(/static/[^"]*)"', page)
    assert sorted(named) == ["/static/studio.css?token=__RL1_STUDIO_TOKEN__",
                             "/static/studio.js?token=__RL1_STUDIO_TOKEN__"]


def test_the_committed_page_is_its_source_copied() -> None:
    # build.mjs copies index.html as it is: held equal without Node.js too, which the
    # rebuild below needs (the wheel ships lsp/studio/static/ and never builds it).
    assert (STUDIO / "src" / "index.html").read_bytes() == (STATIC / "index.html").read_bytes(), (
        "lsp/studio/static/index.html is not editors/studio/src/index.html: "
        "cd editors/studio && npm run build (or copy the file), and commit it")


@pytest.mark.slow  # esbuild bundles CodeMirror
@pytest.mark.needs_node
def test_the_committed_page_is_the_build_of_its_sources(tmp_path: Path) -> None:
    modules = STUDIO / "node_modules"
    if not (modules / ".bin" / "esbuild").exists():
        pytest.skip("editors/studio/node_modules is not installed: `npm ci --ignore-scripts` "
                    "in editors/studio installs it from package-lock.json")
    # A copy of the sources beside a copy of lsp/studio/static's place, so that the
    # build writes there and not over the committed files.
    source = tmp_path / "editors" / "studio"
    shutil.copytree(STUDIO, source, ignore=shutil.ignore_patterns("node_modules"))
    (source / "node_modules").symlink_to(modules)
    built = subprocess.run(["npm", "run", "--silent", "build"], cwd=source,
                           capture_output=True, text=True, timeout=300, check=False)
    assert built.returncode == 0, built.stdout + built.stderr
    out = tmp_path / "lsp" / "studio" / "static"
    assert sorted(path.name for path in out.iterdir()) == sorted(BUILT)
    for name in BUILT:
        assert (out / name).read_bytes() == (STATIC / name).read_bytes(), (
            f"lsp/studio/static/{name} is not the build of editors/studio: "
            "cd editors/studio && npm run build, and commit it")
