"""Ctrl-C reaches the processes the tests start (support/interrupts.py), even when the
suite itself was started with SIGINT ignored, as a shell starts a background job."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

ASKS = ("import signal; "
        "print(signal.getsignal(signal.SIGINT) is signal.default_int_handler)")


def test_a_process_a_test_starts_takes_ctrl_c_as_keyboard_interrupt() -> None:
    assert subprocess.run([sys.executable, "-c", ASKS], capture_output=True, text=True,
                          check=True).stdout == "True\n"


def test_a_suite_started_with_sigint_ignored_gives_its_processes_ctrl_c_back(
        tmp_path: Path) -> None:
    (tmp_path / "test_asks.py").write_text(
        "import subprocess, sys\n"
        "def test_asks():\n"
        f"    out = subprocess.run([sys.executable, '-c', {ASKS!r}], capture_output=True,"
        " text=True).stdout\n"
        "    assert out == 'True\\n', out\n")
    tests = Path(__file__).resolve().parents[1]

    def ignoring_sigint() -> None:  # as a shell starts `make test &`
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    for plugins, status in (([], 1), (["-p", "support.interrupts"], 0)):
        run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                              "-o", "addopts=", *plugins, str(tmp_path / "test_asks.py")],
                             capture_output=True, text=True, cwd=tmp_path,
                             env={"PYTHONPATH": str(tests), "PATH": "/usr/bin:/bin"},
                             preexec_fn=ignoring_sigint)
        assert run.returncode == status, run.stdout + run.stderr
