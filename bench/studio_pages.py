"""The studio's memory as pages come and go: `rl1c studio`, in a process of its own,
serves `/studio` pages one after another (each launches Listing 1 on its world, steps
and sets a breakpoint, and is closed with its run held; tests/studio/served.py). After a
warm-up, prints the server's resident memory per page served, which must stay near zero
(what ended pages leave behind), and, as the reference in the same run, what the server
held after the warm-up; with the processor time the server spends on a page.

    .venv/bin/python bench/studio_pages.py [--pages 300]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "studio")]

from lsp_sessions import processor_seconds  # noqa: E402  (bench/ is this script's folder)
from served import StudioProcess, pages_one_after_another, sample_folder  # noqa: E402  (tests/ on the path just above)
from support.memory import WARM_UP  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pages", type=int, default=300)
    pages = parser.parse_args().pages
    with tempfile.TemporaryDirectory() as folder:
        studio = StudioProcess(sample_folder(Path(folder)))
        try:
            pages_one_after_another(studio, WARM_UP)
            before = studio.resident_mib()
            start = processor_seconds(studio.process.pid)
            pages_one_after_another(studio, pages)
            seconds = processor_seconds(studio.process.pid) - start
            grown = studio.resident_mib() - before
        finally:
            studio.stop()
    print(f"rl1c studio: {pages} pages one after another grew the server by {grown:.1f} MiB, "
          f"{grown / pages:.3f} MiB a page ({grown / pages / before:.3%} of the {before:.0f} "
          f"MiB it held after {WARM_UP} pages); {seconds / pages * 1000:.1f} ms of processor "
          "time a page")


if __name__ == "__main__":
    main()
