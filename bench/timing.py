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


def best_times(actions: list[Callable[[], object]], repeats: int) -> list[float]:
    """The best time of each action, run in turns (one of each a round), so that a burst
    of load elsewhere slows every action alike rather than the one it fell on."""
    best = [float("inf")] * len(actions)
    for _ in range(repeats):
        for index, action in enumerate(actions):
            best[index] = min(best[index], best_time(action, 1))
    return best
