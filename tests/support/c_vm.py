"""The C VM's shared library as tests/c loads it through ctypes: built with UBSan, so
that undefined behaviour aborts the run rather than passing unseen."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rl1.vm import native


def sanitized_library(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The library, built once a pytest worker: the modules that load it share the
    worker's build cache (vm/native.py's, which takes a library it finds there intact);
    the test is skipped on a machine without a C compiler."""
    if not any(shutil.which(cc) for cc in ("gcc", "cc", "clang")):
        pytest.skip("no C compiler (gcc, cc or clang) on this machine: vm/c/install-tools "
                    "installs one on Debian")
    return native.library(tmp_path_factory.getbasetemp() / "c-vm", sanitize=True)
