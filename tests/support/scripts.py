"""Sensor scripts and program starts for the tests that compare engines: the VM and the
interpreter (tests/engines/), the reference VM and the C VM (tests/c/)."""

from __future__ import annotations

from hypothesis import strategies as st

from rl1.vm.device import FuzzyReading, ImageReading, Odometry
from rl1.vm.sensor_script import AFTER_LAST, LossAt, LossDuring, Script

INT16 = st.integers(-32768, 32767)


@st.composite
def scripts(draw: st.DrawFn) -> Script:
    """Readings, and line losses at times or during commands."""
    losses = draw(st.lists(st.builds(LossAt, st.integers(1, 5000))
                           | st.builds(LossDuring, st.sampled_from(("MOV", "MVI")),
                                       st.integers(1, 3), st.integers(1, 2000)), max_size=6))
    return Script(
        images=tuple(draw(st.lists(st.builds(ImageReading, INT16, INT16, INT16, INT16),
                                   max_size=3))),
        odometry=tuple(draw(st.lists(st.builds(Odometry, INT16, INT16, INT16), max_size=2))),
        camera=tuple(draw(st.lists(st.integers(0, 784), max_size=2))),
        ultrasonic={letter: tuple(draw(st.lists(INT16, min_size=1, max_size=2)))
                    for letter in "ABCD"},
        ports={port: (draw(st.integers(0, 255)),) for port in range(0, 0x7E, 7)},
        fuzzy=tuple(draw(st.lists(st.builds(FuzzyReading, INT16, INT16), max_size=2))),
        losses=tuple(losses),
        after_last=draw(st.sampled_from(AFTER_LAST)),  # a run past them ends, or runs on
    )


# Starts that put the vehicle in motion with a tracing mode that jumps, so that more runs
# lose the line (a generated program may lack the handler: a fault both must report).
MOVING_STARTS = ("", "", "(TRC 2); (MOV 1,1)\n", "(TRC 3); (MOV 2,2)\n",
                 "(TRC 2); (MVI 1,1,10)\n", "(TRC 3); (MVI 1,2,30)\n")
