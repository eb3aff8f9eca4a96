"""The memory of a server process a test started, read from /proc: what it holds, what it
has held at its peak, what it holds once done with clients that have left, and what
serving clients one after another leaves it holding; and clients sent at once, whose
peak a test measures."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from pathlib import Path

WARM_UP = 20
"""Clients served before measuring what the others leave: the imports, the caches and the
allocator's first arenas that the first clients cost the server, once."""


def status_mib(pid: int, field: str) -> float:
    """A size of process `pid`'s /proc status in MiB, such as VmRSS (resident memory) or
    VmHWM (the most it has held)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith(f"{field}:"):
            return int(line.split()[1]) / 1024
    raise AssertionError(f"no {field} in /proc/{pid}/status")


SETTLE_SECONDS = 60.0
"""How long a server may take to be done with the clients that have left (a message one
sent, still being read or decoded on a loaded machine) before what it holds is kept."""


def settled_mib(held_mib: Callable[[], float], bound: float,
                seconds: float = SETTLE_SECONDS) -> float:
    """The first of `held_mib`'s readings, a tenth of a second apart, below `bound`; the
    last if none is within `seconds`."""
    deadline = time.monotonic() + seconds
    while (held := held_mib()) >= bound and time.monotonic() < deadline:
        time.sleep(0.1)
    return held


def kept_mib(serve: Callable[[int], None], resident_mib: Callable[[], float],
             clients: int) -> float:
    """What `serve(clients)` (clients one after another) leaves a server holding in MiB,
    after WARM_UP clients served first."""
    serve(WARM_UP)
    before = resident_mib()
    serve(clients)
    return resident_mib() - before


def at_once(clients: int, client: Callable[[], object]) -> None:
    """Run `client` in `clients` threads started together; return once all have ended."""
    threads = [threading.Thread(target=client) for _ in range(clients)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
