"""rl1-mode in a real Emacs: its ERT suite in batch, as editors/emacs/README.md says to
run it, and eglot showing rl1-lsp's diagnostic of a file, set up as the README tells a
user and started as a user starts Emacs, on a terminal.

tests/editors/install-editors installs Emacs and eglot (Debian's emacs-nox and
elpa-eglot) as root; elsewhere, without Emacs, these tests skip.
"""

from __future__ import annotations

import fcntl
import json
import os
import re
import select
import shutil
import signal
import struct
import subprocess
import termios
import time
from pathlib import Path
from typing import Any

import pytest
from support import ROOT
from support.editors import BAD_PROGRAM, SECONDS, editor_environment, the_error

EMACS_MODE = ROOT / "editors" / "emacs"
README = EMACS_MODE / "README.md"
FLYMAKE_DIAGNOSTICS = Path(__file__).with_name("flymake_diagnostics.el")
EMACS = shutil.which("emacs")

pytestmark = pytest.mark.skipif(
    EMACS is None,
    reason="emacs is not installed (as root on Debian, tests/editors/install-editors "
           "installs it)")


def test_the_ert_suite_of_rl1_mode_passes() -> None:
    command = re.search(r"^`(emacs -batch .*)`\.$", README.read_text(encoding="utf-8"),
                        re.MULTILINE)
    assert command is not None, "editors/emacs/README.md no longer says how to run the ERT suite"
    ran = subprocess.run(command[1].split(), cwd=EMACS_MODE, capture_output=True, text=True,
                         timeout=SECONDS)
    output = ran.stdout + ran.stderr
    assert ran.returncode == 0, f"the ERT suite of rl1-mode failed:\n{output}"
    tests = (EMACS_MODE / "rl1-mode-tests.el").read_text(encoding="utf-8").count("(ert-deftest ")
    assert f"Ran {tests} tests, {tests} results as expected, 0 unexpected" in output, output


def _readme_init_file() -> str:
    """The init file of the README's step 3, for this clone of the project."""
    block = re.search(r"```elisp\n(.*?)```", README.read_text(encoding="utf-8"), re.DOTALL)
    assert block is not None, "editors/emacs/README.md has no ```elisp block for the init file"
    return block[1].replace("/path/to/rl1", str(ROOT))


def _run_on_a_terminal(command: list[str], cwd: Path, env: dict[str, str]) -> str:
    """Run `command` with a terminal of 24 lines of 80 columns as its standard streams and
    its controlling terminal (Emacs opens /dev/tty), until it ends or SECONDS pass (then
    it is killed); what it wrote there, decoded."""
    terminal, its_side = os.openpty()
    fcntl.ioctl(its_side, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))
    process = subprocess.Popen(command, cwd=cwd, env=env, stdin=its_side, stdout=its_side,
                               stderr=its_side, start_new_session=True,
                               preexec_fn=lambda: fcntl.ioctl(0, termios.TIOCSCTTY, 0))
    os.close(its_side)
    screen = bytearray()
    deadline = time.monotonic() + SECONDS
    try:
        while time.monotonic() < deadline:
            if select.select([terminal], [], [], 0.1)[0]:
                try:
                    screen += os.read(terminal, 65536)[:65536 - len(screen)]
                except OSError:  # EIO: the process ended and closed the terminal
                    break
            elif process.poll() is not None:
                break
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()
        os.close(terminal)
    return screen.decode("utf-8", "replace")


def test_eglot_shows_rl1_lsps_diagnostic_of_a_file_set_up_as_the_readme_says(
        tmp_path: Path) -> None:
    expected = the_error()
    home = tmp_path / "home"
    (home / ".emacs.d").mkdir(parents=True)
    (home / ".emacs.d" / "init.el").write_text(_readme_init_file(), encoding="utf-8")
    # Not the README's: in a home of its own each time, Emacs 28 would compile Emacs's own
    # libraries to native code again at each start, which a user's does once.
    (home / ".emacs.d" / "early-init.el").write_text(
        "(setq native-comp-deferred-compilation nil)\n", encoding="utf-8")
    project = tmp_path / "robot"
    project.mkdir()
    (project / "bad.rob").write_text(BAD_PROGRAM, encoding="ascii")
    out = tmp_path / "diagnostics.json"
    # A terminal of no terminal emulator that Emacs would query, and wait 2 s for an answer.
    env = editor_environment(home, out) | {"TERM": "vt100"}
    assert EMACS is not None
    screen = _run_on_a_terminal(
        [EMACS, "-nw", "bad.rob", "-l", str(FLYMAKE_DIAGNOSTICS)], project, env)
    assert out.exists(), f"Emacs wrote no diagnostics; its screen:\n{screen}"
    seen: dict[str, Any] = json.loads(out.read_text(encoding="utf-8"))
    assert seen["mode"] == "rl1-mode", f"bad.rob opened in {seen['mode']}:\n{seen['messages']}"
    assert len(seen["diagnostics"]) == 1, (
        f"flymake showed {len(seen['diagnostics'])} diagnostics, not rl1-lsp's one; "
        f"Emacs said:\n{seen['messages']}")
    [shown] = seen["diagnostics"]
    assert (shown["line"], shown["column"]) == (expected.span.line, expected.span.column)
    assert expected.message in shown["text"] and expected.code in shown["text"], shown
    assert re.match(r"\W*rl1\b", shown["text"]), f"not from rl1-lsp: {shown}"
