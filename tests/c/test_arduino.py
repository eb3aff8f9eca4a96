"""The Arduino library (vm/c/arduino/, built by `make -C vm/c arduino-lib`): laid out as
the Arduino library specification (1.5 format) asks, holding the VM's own sources, and
its example sketch, compiled offline for an Arduino Uno by Debian's arduino-builder and
arduino-core-avr (`make -C vm/c arduino`) and run under simavr, prints on the serial
port the calls, the readings, the instruction count and the variables of Listing 1 as
the reference VM's run gives them (`rl1c run examples/sample.rob --sensors
examples/sample.sensors.json`), and builds without a warning at -Wall -Wextra.

Skipped, saying why, where arduino-builder, arduino-core-avr or simavr is missing
(vm/c/install-tools installs them)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from support import ROOT, SAMPLE, SAMPLE_SENSORS
from support.cli import rl1c

C_DIR = ROOT / "vm" / "c"
LIBRARY = "RL1VM"
HARDWARE = Path("/usr/share/arduino/hardware/arduino/avr")
# library.properties: the fields the specification requires, and its categories.
REQUIRED = ("name", "version", "author", "maintainer", "sentence", "paragraph",
            "category", "url", "architectures")
CATEGORIES = ("Display", "Communication", "Signal Input/Output", "Sensors",
              "Device Control", "Timing", "Data Storage", "Data Processing", "Other")
ESCAPE = re.compile(r"\x1b\[[0-9;]*m")


def make(build: Path, target: str) -> str:
    done = subprocess.run(["make", "--no-print-directory", "-C", str(C_DIR), target,
                           f"BUILD={build}", f"RL1_PYTHON={sys.executable}"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


@pytest.fixture(scope="module")
def build(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("arduino")
    make(folder, "arduino-lib")
    return folder


def properties(text: str) -> dict[str, str]:
    return dict(line.split("=", 1) for line in text.splitlines()
                if line and not line.startswith("#"))


def test_the_zip_is_a_library_in_the_1_5_layout(build: Path) -> None:
    with zipfile.ZipFile(build / "RL1VM.zip") as archive:
        names = set(archive.namelist())
        fields = properties(archive.read(f"{LIBRARY}/library.properties").decode("utf-8"))
    assert {name.split("/")[0] for name in names} == {LIBRARY}
    assert all(key in fields for key in REQUIRED)
    assert fields["name"] == LIBRARY and fields["category"] in CATEGORIES
    assert re.fullmatch(r"\d+\.\d+\.\d+", fields["version"])
    assert fields["includes"] == "RL1VM.h" and f"{LIBRARY}/src/RL1VM.h" in names
    # A sketch is a folder of its own name; the library's code is all under src/.
    assert f"{LIBRARY}/examples/Listing1/Listing1.ino" in names
    assert not any(name.endswith((".c", ".cpp", ".h")) and "/src/" not in name
                   and "/examples/" not in name for name in names)


def test_the_library_holds_the_vm_as_it_is(build: Path) -> None:
    source = build / "arduino" / LIBRARY / "src"
    for header in (C_DIR / "rl1vm.h", ROOT / "spec" / "rl1_hardware.h"):
        assert (source / header.name).read_bytes() == header.read_bytes()
    for name in ("rl1vm.c", "rl1vm_load.c"):
        config, line, rest = (source / name).read_bytes().split(b"\n", 2)
        assert config.startswith(b'#include "RL1VM_config.h"')
        assert line == f'#line 1 "{name}"'.encode()
        assert rest == (C_DIR / name).read_bytes()
    # git holds the library's own files alone: the VM's come from vm/c at build time.
    assert not list((C_DIR / "arduino").rglob("rl1vm*"))


def serial_lines(output: str) -> list[str]:
    """What the sketch printed, from simavr's UART log: a line per line, coloured, with
    the carriage return and line feed shown as dots."""
    return [ESCAPE.sub("", line).rstrip(".") for line in output.splitlines()
            if "\x1b[32m" in line]


def reference_lines() -> list[str]:
    run = json.loads(rl1c("run", SAMPLE, "--sensors", SAMPLE_SENSORS, "--format", "json",
                          "--trace", "calls").stdout)
    lines = []
    for entry in run["trace"]:
        args = ",".join(str(arg) for arg in entry["args"])
        line = f"{entry['call']} {args}".rstrip()
        if "result" in entry:
            line += " -> " + " ".join(str(value) for value in entry["result"])
        lines.append(line)
    assert run["status"]["code"] == "ok"
    lines.append(f"ended after {run['instructions']} instructions")
    lines.append("variables: " + " ".join(f"{name}={value}" for name, value
                                          in run["variables"].items() if value))
    return lines


def test_the_example_sketch_runs_listing_1_as_the_reference_vm(build: Path) -> None:
    missing = [tool for tool in ("arduino-builder", "avr-gcc", "simavr")
               if shutil.which(tool) is None]
    if missing or not HARDWARE.is_dir():
        pytest.skip(f"no {' or '.join(missing) or 'arduino-core-avr'} on this machine: "
                    "vm/c/install-tools installs it")
    printed = make(build, "arduino")
    assert "Sketch uses" in printed and "Global variables use" in printed
    # Built with -Wall -Wextra, the library and the sketch are clean (the core is not).
    log = (build / "arduino" / "sketch.log").read_text(encoding="utf-8")
    assert not [line for line in log.splitlines()
                if "warning:" in line and "/cores/arduino/" not in line]
    elf = build / "arduino" / "sketch" / "Listing1.ino.elf"
    # The sketch sleeps with interrupts off when the run is over, which ends simavr.
    done = subprocess.run(["simavr", "-m", "atmega328p", "-f", "16000000", str(elf)],
                          capture_output=True, text=True, timeout=120)
    assert serial_lines(done.stdout + done.stderr) == reference_lines()
    # The program is read from flash: its array is not in RAM (from 0x800000).
    symbols = subprocess.run(["avr-nm", str(elf)], capture_output=True, text=True,
                             check=True).stdout
    address = next(int(line.split()[0], 16) for line in symbols.splitlines()
                   if line.split()[-1].startswith("listing1_ilc"))
    assert address < 0x800000
