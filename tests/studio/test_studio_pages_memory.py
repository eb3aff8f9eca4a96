"""`rl1c studio` serving pages one after another, each closed with its run held, keeps
what they held no longer than an ended language server session (lsp/transports.py,
Collector)."""

from __future__ import annotations

from pathlib import Path

import pytest
from served import StudioProcess, pages_one_after_another, sample_folder

pytestmark = pytest.mark.slow  # a studio in a process of its own, 220 pages

KEPT_BY_200_PAGES_MIB = 10
"""What 200 pages served one after another may leave the server holding: what its
allocator keeps (each page's run took some 0.15 MiB, for good, before the pages were
collected as the sessions are: 29 MiB)."""


def test_pages_one_after_another_leave_nothing_behind(tmp_path: Path) -> None:
    studio = StudioProcess(sample_folder(tmp_path))
    try:
        pages_one_after_another(studio, 20)  # imports, caches, the allocator's arenas
        before = studio.resident_mib()
        pages_one_after_another(studio, 200)
        kept = studio.resident_mib() - before
        assert kept < KEPT_BY_200_PAGES_MIB, f"{kept:.1f} MiB kept by 200 pages"
    finally:
        studio.stop()
