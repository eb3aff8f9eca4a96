"""What the editors' end-to-end tests (tests/editors/) share: a program with one error,
and the environment an editor runs in, with the project's .venv on the PATH as the
editors' READMEs allow and a script of the test's that writes what the editor shows as
JSON to a file."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from rl1.compiler.analysis import analyze
from rl1.compiler.frontend.diagnostics import Diagnostic

BAD_PROGRAM = "A=1\n(FOO 1)\n(END)\n"
SECONDS = 60
"""How long an editor has to show the diagnostic (rl1-lsp starts in about a second)."""


def the_error() -> Diagnostic:
    """The one diagnostic of BAD_PROGRAM, as rl1c check and rl1-lsp find it."""
    [diagnostic] = analyze(BAD_PROGRAM).diagnostics
    return diagnostic


def editor_environment(home: Path, out: Path) -> dict[str, str]:
    """A user's environment, in a home of its own: rl1-lsp on the PATH (from the .venv of
    this Python), and where the test's script writes what the editor shows, which has
    SECONDS less ten to come."""
    return {
        "HOME": str(home),
        "PATH": os.pathsep.join([str(Path(sys.executable).parent), os.environ["PATH"]]),
        "LANG": "C.UTF-8",
        "RL1_DIAGNOSTICS_OUT": str(out),
        "RL1_DIAGNOSTICS_SECONDS": str(SECONDS - 10),
    }
