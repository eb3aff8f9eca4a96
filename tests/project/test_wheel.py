"""The installed package is whole: the wheel `pip install` builds, installed alone in a
fresh virtual environment and run from outside the checkout, runs a program on the C VM
(`rl1c run --engine c` builds it from the sources the wheel ships) and prints every
document its help texts and messages name (`rl1c docs`).

No network: the new environment gets the wheel with --no-deps and finds its dependencies
in this environment's site-packages, through a .pth line (a plain path: the editable
install's own .pth files there are not run, so `rl1` comes from the wheel alone)."""

from __future__ import annotations

import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest
from support import ROOT, SAMPLE, SAMPLE_SENSORS
from support.documents import DOCUMENT_NAME
from support.wheel import built_wheel

from rl1.compiler.cli.main import command_names

pytestmark = [pytest.mark.slow, pytest.mark.needs_cc]


class Installed:
    """The wheel installed in a fresh virtual environment under `folder`."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.bin = folder / "venv" / "bin"
        self.work = folder / "work"  # the working directory: no checkout around it
        self.work.mkdir()
        self.env = {"PATH": f"{self.bin}:/usr/bin:/bin", "HOME": str(folder),
                    "XDG_CACHE_HOME": str(folder / "cache"), "LC_ALL": "C.UTF-8"}

    def run(self, command: str, *args: str | Path) -> subprocess.CompletedProcess[str]:
        return subprocess.run([str(self.bin / command), *map(str, args)], cwd=self.work,
                              env=self.env, capture_output=True, text=True, timeout=300,
                              check=False)


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Installed:
    built = built_wheel(tmp_path_factory)
    assert built.wheel is not None, built.said
    folder = tmp_path_factory.mktemp("wheel")
    venv = folder / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    ours = Path(sysconfig.get_path("purelib"))
    site = venv / ours.relative_to(sys.prefix)  # the same Python: the same layout
    (site / "dependencies.pth").write_text(f"{ours}\n", encoding="utf-8")
    subprocess.run([sys.executable, "-m", "pip", "--python", str(venv / "bin" / "python"),
                    "install", "--no-deps", "--no-index", "--quiet", str(built.wheel)],
                   check=True, capture_output=True)
    return Installed(folder)


def test_rl1_comes_from_the_wheel(installed: Installed) -> None:
    shown = installed.run("python", "-c", "import rl1.vm.native as n; print(n.C_FOLDER)")
    assert shown.returncode == 0, shown.stderr
    assert Path(shown.stdout.strip()).is_relative_to(installed.folder / "venv")


def test_the_wheel_adds_rl1c_studio_through_its_entry_point(installed: Installed) -> None:
    shown = installed.run("python", "-c", "from importlib.metadata import distribution\n"
                          "rl1 = distribution('rl1')\n"
                          "print(rl1.locate_file(''))\n"
                          "for entry in rl1.entry_points.select(group='rl1.commands'):\n"
                          "    print(entry.name, '=', entry.value)")
    assert shown.returncode == 0, shown.stderr
    where, *entries = shown.stdout.splitlines()
    assert Path(where).is_relative_to(installed.folder / "venv")  # the wheel's metadata
    assert entries == ["studio = rl1.lsp.studio.command"]
    helped = installed.run("rl1c", "studio", "--help")
    assert helped.returncode == 0, helped.stderr
    assert helped.stdout.startswith("usage: rl1c studio ")


def test_the_c_engine_runs_a_program_as_the_reference_vm_does(installed: Installed) -> None:
    runs = {engine: installed.run("rl1c", "run", SAMPLE, "--sensors", SAMPLE_SENSORS,
                                  "--engine", engine, "--format", "json")
            for engine in ("vm", "c")}
    assert runs["c"].returncode == 0, runs["c"].stderr
    assert runs["c"].stdout == runs["vm"].stdout
    assert list((installed.folder / "cache" / "rl1").glob("librl1vm-*.so"))


def _named_documents(installed: Installed) -> set[str]:
    said = [installed.run("rl1c", "--help"),
            *(installed.run("rl1c", name, "--help") for name in command_names()),
            installed.run("rl1c", "run", SAMPLE)]  # no sensor script: its help names one
    return {name for shown in said
            for name in DOCUMENT_NAME.findall(" ".join((shown.stdout + shown.stderr).split()))}


def test_every_document_a_help_text_names_is_installed(installed: Installed) -> None:
    named = _named_documents(installed)
    assert {"spec/sensors.md", "spec/simulator.md"} <= named
    for name in sorted(named):
        shown = installed.run("rl1c", "docs", name)
        assert shown.returncode == 0, f"{name}: {shown.stderr}"
        assert shown.stdout == (ROOT / name).read_text(encoding="utf-8"), name


def test_every_guide_and_specification_is_installed(installed: Installed) -> None:
    listed = installed.run("rl1c", "docs")
    assert listed.returncode == 0, listed.stderr
    shipped = {line.split()[1].rstrip(":") for line in listed.stdout.splitlines()}
    in_checkout = {path.relative_to(ROOT).as_posix()
                   for folder in ("docs", "spec") for path in (ROOT / folder).glob("*")
                   if path.suffix in (".md", ".h")}
    assert shipped == in_checkout
