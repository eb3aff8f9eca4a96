"""A run whose pictures show everything they can (tests/sim/test_sim_render.py and the
browser's tests/browser/): an IMG, a scan in place of +40 then -80 then +40 degrees, an
ultrasonic reading with nothing in range and one with an echo from a wall, and the line
lost while tracing in mode 3, which the program takes as a jump to :96 at line 6."""

from __future__ import annotations

from pathlib import Path

from support.cli import rl1c

WORLD = """\
[floor]
size = [800, 500]
[start]
x = 60
y = 150
[[lines]]
name = "guide"
points = [[0, 150], [400, 150]]
[[marks]]
name = "branch"
points = [[200, 151], [204, 151], [204, 161], [200, 161]]
[[stands]]
name = "stand"
x = 300
y = 350
width = 40
depth = 40
facing = -90
[[walls]]
name = "east wall"
points = [[480, 0], [500, 0], [500, 500], [480, 500]]
[[scenes]]
number = 0
sees = ["lines", "marks"]
window = [98, 117, 158, 123]
[limits]
time = 120
"""

PROGRAM = """\
(CAM Z); (CAM D); (SCN 0); (IMG)
(ROT 40); (ROT -80); (ROT 40)
(ULT A)
(TRC 3); (MOV 3,3)
:10 (TIM 1); #10
:96 (MOV 0,0); (ULT A); (IMG); (END)
"""
HANDLER_LINE = 6
SCAN = (40, -80, 40)  # degrees, the turns in place


def draw(folder: Path) -> tuple[Path, Path]:
    """Run the program in the world with `rl1c sim`; its SVG and its replay page."""
    world, program = folder / "scan.world.toml", folder / "scan.rob"
    world.write_text(WORLD)
    program.write_text(PROGRAM)
    picture, page = folder / "scan.svg", folder / "scan.html"
    result = rl1c("sim", program, "--world", world, "--svg", picture, "--html", page)
    assert result.exit_code == 0, result.output
    return picture, page
