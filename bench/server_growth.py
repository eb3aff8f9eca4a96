"""What a server process keeps of the sessions it served, as bench/lsp_sessions.py and
bench/studio_pages.py measure it: after a warm-up, its resident memory and processor time
over sessions served one after another, against what it held after the warm-up."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol, TypeVar

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from support.memory import WARM_UP  # tests/ is put on the path just above


class Served(Protocol):
    """A server in a process of its own (tests/support/hostile.py's ServedLsp,
    tests/studio/served.py's StudioProcess)."""

    process: subprocess.Popen[Any]

    def resident_mib(self) -> float: ...


S = TypeVar("S", bound=Served)


def processor_seconds(pid: int) -> float:
    """User and system time of process `pid` so far."""
    fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def growth(server: S, serve: Callable[[S, int], None], sessions: int, title: str,
           session: str) -> str:
    """Have `serve` serve WARM_UP sessions, then `sessions` more, and say what the server
    grew by and spent on each of those (`session` names one: client, page)."""
    serve(server, WARM_UP)
    before = server.resident_mib()
    start = processor_seconds(server.process.pid)
    serve(server, sessions)
    seconds = processor_seconds(server.process.pid) - start
    grown = server.resident_mib() - before
    return (f"{title}: {sessions} {session}s one after another grew the server by "
            f"{grown:.1f} MiB, {grown / sessions:.3f} MiB a {session} "
            f"({grown / sessions / before:.3%} of the {before:.0f} MiB it held after "
            f"{WARM_UP} {session}s); {seconds / sessions * 1000:.1f} ms of processor time "
            f"a {session}")
