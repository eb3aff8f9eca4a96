"""Planted bugs that the fuzzing and reducing tests must find. The shift bug of
tests/support/broken_vm.py (a negative count shifts left by nothing: `1<-1` gives 1,
not 0): as an `exec:` engine of `rl1c fuzz` (BROKEN_VM), and as an engine in the tests'
own process (BrokenShift), the reference VM at -O0 with that one rule broken. And a C VM
that crashes (crashing_c_vm), for the tests of an engine that ends its process."""

from __future__ import annotations

import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from rl1.compiler.differential import Observation, VmEngine
from rl1.compiler.strategies import Run
from rl1.vm import machine, native

from . import ROOT

BROKEN_VM = (f"exec:{shlex.quote(sys.executable)} "
             f"{shlex.quote(str(ROOT / 'tests/support/broken_vm.py'))} "
             "{ilc} {sensors} {budget}")


class BrokenShift:
    name = "broken-shift"
    level = 0

    def run(self, case: Run, budget: int) -> Observation:
        right = machine._shift_left
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(machine, "_shift_left", lambda value, count: value if count < 0
                          else right(value, count))
            return VmEngine(0).run(case, budget)


# A step after which A is 1234 writes through a null pointer.
CRASHING_STEP = r"""
#include "rl1vm.h"
#undef rl1_step
rl1_state rl1_step(rl1_vm *vm, const rl1_program *program, const rl1_hardware *hw,
                   uint32_t n)
{
    rl1_state state = rl1_step_unplanted(vm, program, hw, n);
    if (vm->V[0] == 1234)
        *(volatile int *)0 = 0;
    return state;
}
"""


def crashing_c_vm(folder: Path) -> Path:
    """The C VM's library built in `folder` with a planted crash: a step after which A
    is 1234 ends the process with SIGSEGV (the test is skipped without a C compiler)."""
    compiler = next((cc for cc in ("cc", "gcc", "clang") if shutil.which(cc)), None)
    if compiler is None:
        pytest.skip("no C compiler")
    planted, library = folder / "planted.c", folder / "librl1vm-planted.so"
    planted.write_text(CRASHING_STEP, encoding="ascii")
    subprocess.run([compiler, *native.FLAGS, f"-I{native.C_FOLDER}",
                    f"-I{native.HEADER_FOLDER}", "-Drl1_step=rl1_step_unplanted", "-o",
                    str(library), *map(str, native.SOURCES), str(planted)], check=True)
    return library
