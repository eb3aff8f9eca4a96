"""An engine double for `rl1c fuzz`'s campaigns: the -O0 VM, writing each program it runs
to a file, from any process (the tests of tests/cli/test_fuzz_campaigns.py and
test_fuzz_crash.py learn so which programs a seed gives, and which were judged)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from rl1.compiler.differential import Observation, VmEngine
from rl1.compiler.strategies import Run


@dataclass(frozen=True)
class Recording:
    """The -O0 VM, appending each program it runs to `path`, a JSON string a line."""

    path: Path
    name: str = "recording"
    level: int = 0

    def run(self, case: Run, budget: int) -> Observation:
        with open(self.path, "a", encoding="utf-8") as stream:
            stream.write(json.dumps(case.source) + "\n")
        return VmEngine(0).run(case, budget)


def recorded(path: Path) -> list[str]:
    """The programs a Recording wrote to `path`, in order."""
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]
