"""Pausing Python's cyclic garbage collector around the front end's bulk work.

Parsing and checking allocate a great many small objects and free none of them in
cycles (the AST is acyclic; the checker's graph refers to blocks by index). The
collector is triggered by allocations, so left on it would walk the growing program
again and again for nothing, and time would grow faster than the file.

Pausing is not enough: what was built while paused is still the youngest generation,
which the next collections walk three times over as it ages (a quarter of the time to
check 100,000 lines, bench/parse_check.py). So the pause ends by moving every object
to the oldest generation at once: `gc.freeze()` then `gc.unfreeze()`, as their docs
say, put all tracked objects in the oldest generation without walking them. Garbage
moved there waits for the next full collection, which CPython starts only once enough
objects have reached that generation the usual way: in a short command that is never,
and nothing is lost; a long-lived process must collect now and then itself (the
language server every so many sessions, a campaign's worker and `rl1c test` every so
many runs: `FullCollections`).
"""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Iterator


@contextlib.contextmanager
def collector_paused() -> Iterator[None]:
    """Run the body with the collector off, and restore it as it was (calls nest)."""
    collecting = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if collecting:
            gc.freeze()
            gc.unfreeze()
            gc.enable()


class FullCollections:
    """A full collection (`collect`) every `every` calls of `count`: for a process that
    runs the front end over and over, whose garbage the pauses move where only a full
    collection frees it."""

    def __init__(self, every: int) -> None:
        self.every = every
        self._since = 0

    def count(self) -> None:
        self._since += 1
        if self._since == self.every:
            self._since = 0
            self.collect()

    def collect(self) -> None:
        gc.collect()
