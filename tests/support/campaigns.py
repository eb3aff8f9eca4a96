"""A cheap campaign whose success rate has a closed form, for the tests of campaigns on
local processes (tests/sim/test_campaign.py) and on a Dask cluster (test_cluster.py)."""

from __future__ import annotations

DROPOUT = 0.3

# A vehicle 30 cm from a wall reads it with sensor A, except when the echo drops out
# (chance DROPOUT) and the reading is the sensor's range, 100: then the program steers
# by 2048 tenths, out of (STX)'s range, a fault at line 4. Nothing else is drawn.
WALL_PROGRAM = """\
A=(ULT A)-99; ?A>#90
(END)
:90 B=A<11
(STX B)
"""
WALL_WORLD = f"""\
[floor]
size = [1000, 1000]
[start]
x = 500.0
y = 500.0
[[walls]]
name = "ahead"
points = [[570, 0], [580, 0], [580, 1000], [570, 1000]]
[noise]
start_cm = 0
start_deg = 0
ultrasonic_cm = 0
ultrasonic_dropout = {DROPOUT}
"""
