"""A world whose answer is known, for sweeps (tests/sim/test_sweep.py) and a campaign's
pictures (test_campaign_pictures.py, bench/campaign_pictures.py): its goal holds the
vehicle within WITHIN cm of a stand's marker, so a program that only waits succeeds
exactly where the stand is near."""

from __future__ import annotations

# The vehicle's camera is 30 cm ahead of its centre, at x = 230; the stand's marker is in
# the middle of its face, 20 cm before its centre: at x = 270, 40 cm from the camera.
HOLD_WORLD = """\
[floor]
size = [1000, 1000]
[start]
x = 200.0
y = 500.0
[[stands]]
name = "bench"
x = 290.0
y = 500.0
facing = 180.0
[goal]
[[goal.hold]]
stand = "bench"
within = 60
seconds = 0.5
"""
CAMERA_TO_MARKER = 40.0
WITHIN = 60.0
WAIT = "(TIM 1); (END)\n"
TURN = "(MOV 0,-3); (TIM 1); (MOV 0,0); (TIM 1); (END)\n"  # a turn to the right, a wait
