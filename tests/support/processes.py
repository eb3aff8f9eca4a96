"""Checks on the processes a test started, read from /proc."""

from __future__ import annotations

import time
from pathlib import Path


def ends_within(pid: int, seconds: float) -> bool:
    """Whether process `pid` is gone or a zombie within `seconds`. A SIGKILL sent to a
    process group is delivered asynchronously: a child may still show as running just
    after `killpg` returns."""
    deadline = time.monotonic() + seconds
    stat_file = Path(f"/proc/{pid}/stat")
    while time.monotonic() < deadline:
        try:
            if stat_file.read_text().rsplit(")", 1)[1].split()[0] == "Z":
                return True
        except FileNotFoundError:
            return True
        time.sleep(0.05)
    return False
