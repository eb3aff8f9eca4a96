"""`make -C vm/c port-check HW=...`: the conformance vectors with a port's fake vehicle in
place of the reference one (vm/c/test/scripted.c), naming the device's duty a failing
vector shows broken (vm/c/README.md's table; vm/c/test/duties.py)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from support import ROOT

C_FOLDER = ROOT / "vm" / "c"
REFERENCE = C_FOLDER / "test" / "scripted.c"

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None and shutil.which("cc") is None,
                                reason="no C compiler: vm/c/install-tools installs one")


def port_check(hw: Path, build: Path, started_in: Path | None = None
               ) -> subprocess.CompletedProcess[str]:
    """`make -C vm/c port-check HW=hw`, make started from a shell in `started_in` (a
    relative `hw` names a file there, as docs/firmware.md has the user write it; the
    Makefile finds the folder in PWD, which a shell sets)."""
    shell = {**os.environ, "PWD": str(started_in)} if started_in else None
    return subprocess.run(["make", "-s", "-C", str(C_FOLDER), "port-check", f"HW={hw}",
                           f"BUILD={build}", f"PYTHON={sys.executable}"], cwd=started_in,
                          env=shell, capture_output=True, text=True, check=False, timeout=600)


def broken_port(tmp_path: Path, old: str, new: str) -> Path:
    """The reference fake vehicle with `old` (found once) replaced by `new`."""
    text = REFERENCE.read_text(encoding="utf-8")
    assert text.count(old) == 1
    hw = tmp_path / "my_hw.c"
    hw.write_text(text.replace(old, new).replace('#include "scripted.h"',
                                                 f'#include "{REFERENCE.parent}/scripted.h"'),
                  encoding="utf-8")
    return hw


def test_the_reference_fake_vehicle_keeps_every_duty(tmp_path: Path) -> None:
    done = port_check(REFERENCE, tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "port-check: every duty kept (conformance: " in done.stdout


def test_a_port_that_does_not_stop_in_mode_2_is_told_so(tmp_path: Path) -> None:
    hw = broken_port(tmp_path, "    if (d->mode == 2u) {\n        d->motion = 0;",
                     "    if (d->mode == 99u) {\n        d->motion = 0;")
    done = port_check(Path(hw.name), tmp_path, started_in=hw.parent)
    assert done.returncode != 0
    verdicts = re.findall(r"^port-check: (.*)$", done.stdout, re.MULTILINE)
    assert verdicts and all("11 (mode 2: the device stops the vehicle itself)" in verdict
                            for verdict in verdicts), done.stdout
    assert "mode-2-lost-during-mov" in done.stdout


def test_a_port_file_not_found_is_said_with_where_it_was_looked_for(tmp_path: Path) -> None:
    """make -C runs in vm/c, where the user's relative HW= was not found: cc1 failed."""
    done = port_check(Path("my_hw.c"), tmp_path, started_in=tmp_path)
    assert done.returncode != 0
    assert f"port-check: no file {tmp_path}/my_hw.c: HW= names the C file" in done.stderr
    assert "cc1" not in done.stderr


def test_a_port_whose_mvi_waits_through_a_loss_is_told_so(tmp_path: Path) -> None:
    hw = broken_port(tmp_path, "return advance(d, d->motion_end - d->time, true);",
                     "return advance(d, d->motion_end - d->time, false);")
    done = port_check(hw, tmp_path)
    assert done.returncode != 0
    assert "13 (a TIM or MVI in progress answers its next poll OK when a loss is posted)" \
        in done.stdout, done.stdout
