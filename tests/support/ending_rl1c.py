"""`rl1c` with one more engine, for the tests of `rl1c reduce` when an engine ends the
process it runs in: `ends-on:LINE`, the -O0 VM, except on a program that has the line
LINE, where it ends its process by SIGSEGV, as the C VM crashing would. With the
environment variable RL1_TEST_HOLD naming a file, on the program that is LINE alone it
first creates that file and holds for HOLD_SECONDS (a test sends Ctrl-C meanwhile).

    python ending_rl1c.py [--c-library PATH] ARGS...

runs `rl1c ARGS...` in a process of its own, so that a test whose rl1c does not outlive
the engine fails rather than ending pytest; with --c-library, the C VM's library is the
one at PATH (one with a planted bug) instead of one built."""

from __future__ import annotations

import faulthandler
import os
import signal
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

from rl1.compiler import differential
from rl1.compiler.cli.main import rl1c
from rl1.compiler.differential import Engine, Observation, VmEngine
from rl1.compiler.strategies import Run
from rl1.vm import native

PREFIX = "ends-on:"
HOLD = "RL1_TEST_HOLD"
HOLD_SECONDS = 5


@dataclass(frozen=True)
class EndsOnLine:
    """The -O0 VM, ending its process on a program with the line `line`."""

    line: str
    level: int = 0

    @property
    def name(self) -> str:
        return PREFIX + self.line

    def run(self, case: Run, budget: int) -> Observation:
        lines = case.source.splitlines()
        if self.line in lines:
            hold = os.environ.get(HOLD)
            if hold is not None and lines == [self.line]:
                Path(hold).touch()
                time.sleep(HOLD_SECONDS)
            faulthandler.disable()  # so that the signal ends the process, printing nothing
            os.kill(os.getpid(), signal.SIGSEGV)
        return VmEngine(0).run(case, budget)


def main(arguments: list[str]) -> None:
    named = differential.engine_named

    def engine_named(name: str) -> Engine | None:
        return EndsOnLine(name[len(PREFIX):]) if name.startswith(PREFIX) else named(name)

    differential.engine_named = engine_named
    if arguments[:1] == ["--c-library"]:
        planted = Path(arguments[1])
        patch = pytest.MonkeyPatch()  # for this process's life
        # Where the c-ON engines find it, and where rl1c reduce loads it first.
        for module in (differential, native):
            patch.setattr(module, "library", lambda: planted)
        arguments = arguments[2:]
    rl1c.main(arguments, prog_name="rl1c")


if __name__ == "__main__":
    main(sys.argv[1:])
