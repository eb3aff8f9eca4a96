"""`make -C vm/c port-check HW=...`: the conformance vectors with a port's fake vehicle in
place of the reference one (vm/c/test/scripted.c), naming the device's duty a failing
vector shows broken (vm/c/README.md's table; vm/c/test/duties.py)."""

from __future__ import annotations

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


def port_check(hw: Path, build: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["make", "-s", "-C", str(C_FOLDER), "port-check", f"HW={hw}",
                           f"BUILD={build}", f"PYTHON={sys.executable}"],
                          capture_output=True, text=True, check=False, timeout=600)


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
    done = port_check(hw, tmp_path)
    assert done.returncode != 0
    verdicts = re.findall(r"^port-check: (.*)$", done.stdout, re.MULTILINE)
    assert verdicts and all("11 (mode 2: the device stops the vehicle itself)" in verdict
                            for verdict in verdicts), done.stdout
    assert "mode-2-lost-during-mov" in done.stdout


def test_a_port_whose_mvi_waits_through_a_loss_is_told_so(tmp_path: Path) -> None:
    hw = broken_port(tmp_path, "return advance(d, d->motion_end - d->time, true);",
                     "return advance(d, d->motion_end - d->time, false);")
    done = port_check(hw, tmp_path)
    assert done.returncode != 0
    assert "13 (a TIM or MVI in progress answers its next poll OK when a loss is posted)" \
        in done.stdout, done.stdout
