"""editors/nvim in a real Neovim: set up as its README's init.lua says, Neovim's own LSP
client shows rl1-lsp's diagnostic of a file.

Debian 12's Neovim is 0.7.2 (tests/editors/install-editors installs it as root; without
Neovim, this test skips), so this runs the plugin's path for 0.7 to 0.10; no registry this
project reaches has a Neovim of 0.11 or newer from its makers, so that path (vim.lsp.config
and vim.lsp.enable) is not run here.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest
from support import ROOT
from support.editors import BAD_PROGRAM, SECONDS, editor_environment, the_error

README = ROOT / "editors" / "nvim" / "README.md"
LSP_DIAGNOSTICS = Path(__file__).with_name("lsp_diagnostics.lua")
NVIM = shutil.which("nvim")

pytestmark = pytest.mark.skipif(
    NVIM is None,
    reason="nvim is not installed (as root on Debian, tests/editors/install-editors "
           "installs it)")


# What the README's steps 2 and 3 put in init.lua: the folder on the runtime path, setup().
_INIT_LINES = (r"vim\.opt\.runtimepath:append\([^`]*\)", r"require\('rl1'\)\.setup\(\)")


def _readme_init_file() -> str:
    """The init.lua of the README's set-up (steps 2 and 3), for this clone of the project."""
    set_up = README.read_text(encoding="utf-8").split("## Set-up", 1)[-1]
    lines = [re.search(rf"`({pattern})`", set_up) for pattern in _INIT_LINES]
    assert all(lines), "editors/nvim/README.md's set-up no longer gives init.lua's two lines"
    return "".join(f"{line[1]}\n" for line in lines if line).replace("/path/to/rl1", str(ROOT))


def test_neovim_shows_rl1_lsps_diagnostic_of_a_file_set_up_as_the_readme_says(
        tmp_path: Path) -> None:
    expected = the_error()
    init = tmp_path / "init.lua"
    init.write_text(_readme_init_file(), encoding="utf-8")
    # The workspace root is the folder of rl1.toml, above the file's and below the
    # working directory.
    project = tmp_path / "robot"
    (project / "programs").mkdir(parents=True)
    (project / "rl1.toml").write_text("", encoding="utf-8")
    (project / "programs" / "bad.rob").write_text(BAD_PROGRAM, encoding="ascii")
    out = tmp_path / "diagnostics.json"
    assert NVIM is not None
    ran = subprocess.run(
        [NVIM, "--headless", "-u", str(init), "robot/programs/bad.rob",
         "-c", f"luafile {LSP_DIAGNOSTICS}"],
        cwd=tmp_path, env=editor_environment(tmp_path, out), stdin=subprocess.DEVNULL,
        capture_output=True, text=True, timeout=SECONDS)
    assert out.exists(), f"Neovim wrote no diagnostics:\n{ran.stdout}{ran.stderr}"
    seen: dict[str, Any] = json.loads(out.read_text(encoding="utf-8"))
    said = f"Neovim said:\n{seen['messages']}\n{ran.stderr}"
    assert seen["filetype"] == "rl1", said
    assert seen["clients"] == [{"name": "rl1", "root": str(project)}], said
    assert len(seen["diagnostics"]) == 1, (
        f"Neovim has {len(seen['diagnostics'])} diagnostics, not rl1-lsp's one; {said}")
    [shown] = seen["diagnostics"]
    assert (shown["line"], shown["column"]) == (expected.span.line, expected.span.column)
    assert (shown["source"], shown["code"]) == ("rl1", expected.code)
    assert shown["message"].startswith(expected.message), shown
