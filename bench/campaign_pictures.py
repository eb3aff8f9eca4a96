"""The memory of a campaign's pictures (`rl1c sim --runs N --svg --html`,
vm/sim/campaign_render.py): the peak resident size of the command and the sizes of its
pictures for a campaign of N runs and of 10 N, with and without pictures, so the ratio
shows that a picture keeps a bounded sample (500 paths of 64 points, 2,000 failures)
whatever the campaign's size. The runs are cheap: a program that waits a second in a
world whose stand [vary] draws near or far, so about half of them fail.

    .venv/bin/python bench/campaign_pictures.py [--runs N]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from support.hold import HOLD_WORLD, TURN  # noqa: E402  (tests/ is put on the path just above)

RL1C = str(Path(sys.executable).with_name("rl1c"))
WORLD = HOLD_WORLD + """\
[vary]
stands.bench.x = { uniform = [0, 45] }
start.y = { normal = [0, 5] }
"""


def peak(args: list[str]) -> tuple[float, float]:
    """The peak resident size (MB) and the seconds of `rl1c` with `args`, alone."""
    script = ("import resource, subprocess, sys, time; started = time.perf_counter(); "
              "subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL, "
              "stderr=subprocess.DEVNULL); print(resource.getrusage("
              "resource.RUSAGE_CHILDREN).ru_maxrss / 1024, time.perf_counter() - started)")
    out = subprocess.run([sys.executable, "-c", script, RL1C, *args], check=True,
                         capture_output=True, text=True).stdout.split()
    return float(out[0]), float(out[1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=1_000)
    runs = parser.parse_args().runs
    with tempfile.TemporaryDirectory() as folder:
        program, world = Path(folder, "p.rob"), Path(folder, "w.world.toml")
        program.write_text(TURN)
        world.write_text(WORLD)
        for count in (runs, 10 * runs):
            base = ["sim", str(program), "--world", str(world), "--runs", str(count),
                    "--jobs", "1"]
            plain, _ = peak(base)
            svg, html = Path(folder, f"{count}.svg"), Path(folder, f"{count}.html")
            pictured, seconds = peak([*base, "--svg", str(svg), "--html", str(html)])
            print(f"{count:>7,} runs: peak {plain:.1f} MB without pictures, {pictured:.1f} MB "
                  f"with (x{pictured / plain:.2f}), {seconds:.1f} s; svg "
                  f"{svg.stat().st_size / 1024:.0f} KiB, html "
                  f"{html.stat().st_size / 1024:.0f} KiB")


if __name__ == "__main__":
    main()
