"""What the Dask workers of tests/sim/test_cluster.py's campaigns that end their workers
load first (`dask worker --preload support.cluster_worker`, with tests/ on PYTHONPATH):
the C VM of $PLANTED_C_VM (support.planted.crashing_c_vm's library) when it is set, and
`EndsItsWorker`, an engine that ends the worker whatever program it judges, there or in
a process the worker made to run a task or judge a program apart (which rl1 starts
importing this module, as the worker preloaded it)."""

from __future__ import annotations

import os
import signal
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rl1.compiler import differential
from rl1.compiler.differential import Observation, VmEngine
from rl1.compiler.strategies import Run

PLANTED = "PLANTED_C_VM"  # the environment variable naming the library
WORKER = "RL1_TEST_DASK_WORKER"  # the worker's process id, for the processes it starts


def _planted(*args: object, **kwargs: object) -> Path:
    return Path(os.environ[PLANTED])


if os.environ.get(PLANTED):  # as the tests' monkeypatch does in their own process
    differential.library = _planted  # type: ignore[attr-defined]


def dask_setup(worker: Any) -> None:
    """Dask's call when the worker starts, in its process."""
    os.environ[WORKER] = str(os.getpid())


@dataclass(frozen=True)
class EndsItsWorker:
    name: str = "ends-its-worker"
    level: int = 0

    def run(self, case: Run, budget: int) -> Observation:
        if WORKER not in os.environ:
            raise RuntimeError("EndsItsWorker runs only on a worker that preloaded it")
        os.kill(int(os.environ[WORKER]), signal.SIGKILL)
        return VmEngine(0).run(case, budget)
