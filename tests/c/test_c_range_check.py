"""A variable argument's range is checked with one unsigned comparison (rl1vm.h's
rl1_in_range: value - low <= span); it must mean low <= value <= high for every int16_t
value and every parameter, where int has 32 bits and where it has 16 (AVR), on which the
difference wraps at 2^16 instead. vm/c/test/range_check.c compares the two for all of
them, built for the host and, when avr-gcc and simavr are here (vm/c/install-tools),
for the ATmega328P and run under simavr."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest
from support import ROOT

from rl1.vm import isa_table

C_DIR = ROOT / "vm" / "c"
WARN = ["-I../../spec", "-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror",
        "-Wconversion", "-Wsign-conversion"]
SOURCES = ["rl1vm_load.c", "test/range_check.c"]
HOST_MAIN = """#include <stdio.h>
#include "target.h"
void target_print(const char *text) { fputs(text, stdout); }
int main(void) { return target_run(); }
"""
AVR = ["avr-gcc", "-mmcu=atmega328p", "-Os", "-DRL1_READ_BYTE(p)=pgm_read_byte(p)",
       "-include", "avr/pgmspace.h", "-DTARGET_FLASH=PROGMEM", "test/avr_start.c"]


def every_value_of_every_range() -> int:
    ranges = sum(len(info.form.params) for info in isa_table.calls() if info.form)
    return ranges * 65536


def checked_and_wrong(output: str) -> tuple[int, int]:
    found = re.search(r"range: (\d+) (\d+)", output)
    assert found is not None, output
    return int(found.group(1)), int(found.group(2))


def test_on_the_host(tmp_path: Path) -> None:
    compiler = shutil.which("gcc") or shutil.which("cc") or shutil.which("clang")
    if compiler is None:
        pytest.skip("no C compiler on this machine: vm/c/install-tools installs one")
    main = tmp_path / "main.c"
    main.write_text(HOST_MAIN, encoding="ascii")
    binary = tmp_path / "range_check"
    subprocess.run([compiler, *WARN, "-Itest", "-o", str(binary), *SOURCES, str(main)],
                   cwd=C_DIR, check=True)
    run = subprocess.run([str(binary)], capture_output=True, text=True, check=False)
    assert checked_and_wrong(run.stdout) == (every_value_of_every_range(), 0)
    assert run.returncode == 0


def test_where_int_has_16_bits(tmp_path: Path) -> None:
    missing = [tool for tool in ("avr-gcc", "simavr") if shutil.which(tool) is None]
    if missing:
        pytest.skip(f"no {', '.join(missing)} on this machine: vm/c/install-tools "
                    "installs them")
    elf = tmp_path / "range_check.elf"
    subprocess.run([*AVR, *WARN, "-Itest", "-o", str(elf), *SOURCES], cwd=C_DIR, check=True)
    # the firmware sleeps with interrupts off once it has printed, which ends simavr
    run = subprocess.run(["simavr", "-m", "atmega328p", "-f", "16000000", str(elf)],
                         capture_output=True, text=True, errors="replace", timeout=600,
                         check=False)
    assert checked_and_wrong(run.stdout + run.stderr) == (every_value_of_every_range(), 0)
