"""The set-up the guides give for editors matches what the code needs: the commands that
pipx puts on the PATH, the Neovim versions that editors/nvim tells apart, and eglot,
which Emacs before 29 does not have."""

import re
import tomllib

from support import ROOT

EDITORS = ROOT / "editors"


def _section(markdown: str, title: str) -> str:
    found = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", markdown,
                      re.MULTILINE | re.DOTALL)
    assert found is not None, f"no section `## {title}`"
    return found[1]


def test_the_editors_guide_installs_every_command_with_pipx() -> None:
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))[
        "project"]["scripts"]
    section = _section((ROOT / "docs" / "editors.md").read_text(encoding="utf-8"),
                       "Installing `rl1c`, `rl1-lsp` and `rl1-dap` on the PATH")
    assert "pipx install /path/to/rl1" in section and "pipx install -e" in section
    missing = [name for name in scripts if f"`{name}`" not in section]
    assert not missing, f"the pipx section of docs/editors.md does not name {missing}"


def test_the_neovim_readme_names_every_version_the_plugin_tells_apart() -> None:
    plugin = (EDITORS / "nvim" / "lua" / "rl1" / "init.lua").read_text(encoding="utf-8")
    gates = set(re.findall(r"has\('nvim-(\d+\.\d+)'\)", plugin))
    assert gates, "init.lua checks no Neovim version"
    versions = _section((EDITORS / "nvim" / "README.md").read_text(encoding="utf-8"),
                        "Versions")
    minimum = min(gates, key=lambda version: tuple(map(int, version.split("."))))
    major, minor = minimum.split(".")
    older = f"{major}.{int(minor) - 1}"
    for version in sorted(gates | {older}):
        assert re.search(rf"^\| {re.escape(version)}\b", versions, re.MULTILINE), (
            f"editors/nvim/README.md: no row of the Versions table starts with {version}")


def test_the_emacs_readme_installs_eglot_where_it_is_not_built_in() -> None:
    readme = (EDITORS / "emacs" / "README.md").read_text(encoding="utf-8")
    assert "eglot-ensure" in readme
    assert "Emacs 26, 27 and 28" in readme and "M-x package-install RET eglot RET" in readme
