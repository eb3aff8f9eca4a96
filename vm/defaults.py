"""The defaults and choices of the compile and run options, each written once.

The stages and the command line import them from here: this module imports nothing, so
that `rl1c` spells its options without loading the back end or the VM
(bench/cold_start.py).
"""

from __future__ import annotations

from typing import Literal

DEFAULT_LEVEL = 1
"""The optimization level a program is compiled at unless told (spec/optimization.md):
by `rl1c compile`, by `compile_text`, and before `rl1c run` and `rl1c sim` run it."""

DEFAULT_BUDGET = 10_000_000
"""Steps a run may take before the watchdog ends it: VM instructions, or interpreter
statements. Both engines look at the count when a jump is taken and before a device call
runs (every loop takes a jump); since they count different steps, they stop a runaway
program at different points."""

DEFAULT_TIME_LIMIT_MS = 3_600_000
"""The device-time limit of `rl1c run`: an hour, far beyond any test a script writes
(Listing 1 takes 13 s), and reached in a second or two by a runaway loop of (TIM 1)."""

Engine = Literal["vm", "ast", "c"]
ENGINES: tuple[Engine, ...] = ("vm", "ast", "c")
"""What runs a program: the reference VM (after compiling a .rob file), the AST
interpreter, or the C VM of the firmware through ctypes."""

TraceChoice = Literal["short", "all", "calls", "none"]
TRACE_CHOICES: tuple[TraceChoice, ...] = ("short", "all", "calls", "none")
"""Which entries of a run's trace a report shows (`--trace` of `rl1c run` and `rl1c sim`)."""
