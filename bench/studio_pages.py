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

from served import StudioProcess, pages_one_after_another, sample_folder  # noqa: E402  (tests/ on the path just above)
from server_growth import growth  # noqa: E402  (bench/ is this script's folder)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pages", type=int, default=300)
    pages = parser.parse_args().pages
    with tempfile.TemporaryDirectory() as folder:
        studio = StudioProcess(sample_folder(Path(folder)))
        try:
            print(growth(studio, pages_one_after_another, pages, "rl1c studio", "page"))
        finally:
            studio.stop()


if __name__ == "__main__":
    main()
