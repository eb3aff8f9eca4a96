"""A pytest plugin every run loads (pyproject.toml's addopts): Hypothesis without deadlines.

A deadline is a timed assertion, and the suite runs on shared machines whose load can
make any example slow: properties check what a program does, never how fast (speed is
bench/'s business)."""

from hypothesis import settings

settings.register_profile("rl1", deadline=None)
settings.load_profile("rl1")
