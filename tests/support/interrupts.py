"""A pytest plugin every run loads (pyproject.toml's addopts): Ctrl-C works again in
the processes the tests start.

A shell starts a background job (`make test &`, `nohup make test &`, many CI runners)
with SIGINT ignored, and an ignored signal stays ignored across fork and exec. The
tests that stop `rl1c studio`, `rl1c reduce` or a campaign with SIGINT, as a user's
Ctrl-C would, then saw it ignored: the studio never ended, and reduce ran to its end.
Python itself turns SIGINT into KeyboardInterrupt only when it starts with SIGINT not
ignored, so the suite sets it back to that before any test starts a process."""

from __future__ import annotations

import signal


def pytest_configure() -> None:
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
