"""A full disk under standard output (`rl1c check x.rob > /dev/full`) is a one-line error
and exit status 2 for every command that writes there, never an internal error."""

import os
import subprocess
import sys
from pathlib import Path

import pytest
from support import SAMPLE, SAMPLE_SENSORS

RL1C = str(Path(sys.executable).with_name("rl1c"))

pytestmark = pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("full") / "sample.ilc"
    subprocess.run([RL1C, str(SAMPLE), "-o", str(target)], check=True, capture_output=True)
    return target


@pytest.mark.parametrize("arguments", [
    ["check", "{sample}"],
    ["check", "--format", "sarif", "{sample}"],
    ["dis", "{ilc}"],
    ["run", "{ilc}", "--sensors", "{sensors}"],
    ["fmt", "-"],
    ["{sample}", "-o", "-"],
    ["{sample}", "--emit", "ir", "-o", "-"],
    ["explain", "W0301"],
    ["explain", "--list"],
    ["--help"],
    ["--version"],
])
def test_a_full_disk_is_one_line_and_status_2(arguments: list[str], compiled: Path) -> None:
    argv = [part.format(sample=SAMPLE, ilc=compiled, sensors=SAMPLE_SENSORS)
            for part in arguments]
    with open("/dev/full", "w") as full:
        done = subprocess.run([RL1C, *argv], stdin=SAMPLE.open("rb"), stdout=full,
                              stderr=subprocess.PIPE, text=True, check=False)
    assert done.returncode == 2, done.stderr
    last = done.stderr.splitlines()[-1]
    assert last == ("rl1c: error: cannot write the output: No space left on device; "
                    "free some space or write elsewhere")
    assert "internal error" not in done.stderr and "Traceback" not in done.stderr
