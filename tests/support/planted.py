"""The planted shift bug of tests/support/broken_vm.py (a negative count shifts left by
nothing: `1<-1` gives 1, not 0), which the fuzzing and reducing tests must find: as an
`exec:` engine of `rl1c fuzz` (BROKEN_VM), and as an engine in the tests' own process
(BrokenShift), the reference VM at -O0 with that one rule broken."""

from __future__ import annotations

import shlex
import sys

import pytest

from rl1.compiler.differential import Observation, VmEngine
from rl1.compiler.strategies import Run
from rl1.vm import machine

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
