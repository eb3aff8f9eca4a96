"""`make demo` prints what a user wants to read: the commands as they would type them and
their output, with no recipe echoed and no diagnostic twice."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

from support import ROOT

MAKEFILE = (ROOT / "Makefile").read_text(encoding="utf-8")


def _recipe(target: str) -> list[str]:
    found = re.search(rf"^{re.escape(target)}:.*\n((?:\t.*\n)+)", MAKEFILE, re.MULTILINE)
    assert found is not None, f"no rule for {target} in the Makefile"
    return found[1].splitlines()


def test_the_setup_and_the_demo_echo_no_recipe_line() -> None:
    for target in ("$(STAMP)", "demo"):
        loud = [line for line in _recipe(target) if not line.startswith("\t@")]
        assert not loud, f"make would echo these lines of {target}: {loud}"


def test_the_demo_shows_each_command_and_each_warning_once(tmp_path: Path) -> None:
    shutil.copy(ROOT / "Makefile", tmp_path)
    shutil.copy(ROOT / "pyproject.toml", tmp_path)
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    stamp = tmp_path / "installed"  # newer than pyproject.toml: no set-up
    stamp.touch()
    demo = subprocess.run(["make", "--no-print-directory", "demo", f"STAMP={stamp}",
                           f"BIN={Path(sys.executable).parent}"],
                          cwd=tmp_path, capture_output=True, text=True, check=False)
    assert demo.returncode == 0, demo.stderr
    shown = demo.stdout + demo.stderr
    assert re.findall(r"^\$ (.*)$", shown, re.MULTILINE) == [
        "rl1c examples/sample.rob -o build/sample.ilc",
        "rl1c run build/sample.ilc --sensors examples/sample.sensors.json",
        "rl1c sim build/sample.ilc --world examples/sample.world.toml --svg build/sample.svg "
        "--html build/sample.html > build/sample.sim.txt",
    ]
    codes = re.findall(r"^warning\[(\w+)\]", shown, re.MULTILINE)
    assert codes and len(codes) == len(set(codes)), codes
    assert "the program ended normally" in demo.stdout
    assert (tmp_path / "build" / "sample.ilc").is_file()
    assert (tmp_path / "build" / "sample.svg").is_file()
