"""Timing shared by the benchmarks: on a shared, noisy machine the fastest of several
runs is the one least disturbed, so that is the figure the benchmarks compare."""

from __future__ import annotations

import gc
import time
from collections.abc import Callable


def best_time(action: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        gc.collect()
        start = time.perf_counter()
        action()
        times.append(time.perf_counter() - start)
    return min(times)
