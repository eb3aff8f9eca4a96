"""`rl1c studio`'s memory as pages come and go: serving pages one after another, each
closed with its run held, it keeps what they held no longer than an ended language
server session (lsp/transports.py, Collector); pages sending their largest messages at
once take no more than the language server's sessions may (transports.InFlight)."""

from __future__ import annotations

import functools
from pathlib import Path

import pytest
from served import TIMEOUT, StudioProcess, pages_one_after_another, sample_folder
from support.hostile import GROWTH_BOUND_MIB
from support.memory import at_once, kept_mib
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from rl1.lsp.transports import MAX_SESSIONS

pytestmark = pytest.mark.slow  # a studio in a process of its own, 220 pages

KEPT_BY_200_PAGES_MIB = 10
"""What 200 pages served one after another may leave the server holding: what its
allocator keeps (each page's run took some 0.15 MiB, for good, before the pages were
collected as the sessions are: 29 MiB)."""


def test_pages_one_after_another_leave_nothing_behind(tmp_path: Path) -> None:
    studio = StudioProcess(sample_folder(tmp_path))
    try:
        kept = kept_mib(functools.partial(pages_one_after_another, studio),
                        studio.resident_mib, 200)
        assert kept < KEPT_BY_200_PAGES_MIB, f"{kept:.1f} MiB kept by 200 pages"
    finally:
        studio.stop()


def test_pages_sending_a_compressed_message_of_60_mib_at_once_stay_in_the_bound(
        tmp_path: Path) -> None:
    """Found by the hostile pass: permessage-deflate carried each message in some 60 KiB,
    which is what the bound of the bytes in flight counted, and the server inflated the
    eight of them at once: 1,134 MiB at its peak."""
    studio = StudioProcess(sample_folder(tmp_path))
    started = studio.resident_mib()
    text = "\\u0041" * (10 * 2**20)  # 60 MiB of JSON escapes, 10 MiB of text
    message = ('{"jsonrpc": "2.0", "id": 1, "method": "files/save", "params": '
               f'{{"path": "large.rob", "text": "{text}"}}}}')
    answered: list[str] = []

    def send() -> None:
        try:
            with connect(studio.url("/studio"), max_size=None, open_timeout=TIMEOUT) as page:
                page.send(message)
                answered.append(str(page.recv(timeout=TIMEOUT)))
        except (ConnectionClosed, OSError):  # refused while the others are read
            pass

    try:
        at_once(MAX_SESSIONS, send)
        peak = studio.peak_mib() - started
        assert peak < GROWTH_BOUND_MIB, f"{peak:.0f} MiB at its peak"
        assert answered and all("larger than 8 MiB" in answer for answer in answered)
    finally:
        studio.stop()
