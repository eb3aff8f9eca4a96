"""`rl1c(*args)`: runs the `rl1c` command line in the test process, as a terminal-less
shell would, and returns what it printed and its exit status."""

from __future__ import annotations

import io
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from rl1.compiler.cli import main as cli

if TYPE_CHECKING:
    from _typeshed import ReadableBuffer


@dataclass(frozen=True)
class Result:
    exit_code: int
    stdout_bytes: bytes
    stderr_bytes: bytes
    output_bytes: bytes  # standard output and error as they were interleaved
    encoding: str

    @property
    def stdout(self) -> str:
        return self.stdout_bytes.decode(self.encoding)

    @property
    def stderr(self) -> str:
        return self.stderr_bytes.decode(self.encoding)

    @property
    def output(self) -> str:
        return self.output_bytes.decode(self.encoding)


class _Tee(io.BytesIO):
    """Keeps what is written, and copies it to `both` as well."""

    def __init__(self, both: io.BytesIO) -> None:
        super().__init__()
        self.both = both

    def write(self, data: ReadableBuffer) -> int:
        self.both.write(data)
        return super().write(data)


def rl1c(*args: str | Path, stdin: bytes = b"", encoding: str = "utf-8",
         env: dict[str, str | None] | None = None) -> Result:
    """Runs `rl1c args...` reading `stdin`, with standard streams in `encoding` and the
    environment variables `env` set (None: unset) for the run."""
    both = io.BytesIO()
    stdout, stderr = _Tee(both), _Tee(both)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(stdin), encoding=encoding))
        patch.setattr(sys, "stdout", io.TextIOWrapper(stdout, encoding=encoding,
                                                      write_through=True))
        patch.setattr(sys, "stderr", io.TextIOWrapper(stderr, encoding=encoding,
                                                      write_through=True))
        for name, value in (env or {}).items():
            if value is None:
                patch.delenv(name, raising=False)
            else:
                patch.setenv(name, value)
        try:
            status = cli.main([str(arg) for arg in args])
        except SystemExit as done:  # --help, --version, a malformed command line
            assert isinstance(done.code, int), done.code
            status = done.code
        sys.stdout.flush()
        sys.stderr.flush()
        # Read before the streams are put back: dropping the wrappers closes the buffers.
        return Result(status, stdout.getvalue(), stderr.getvalue(), both.getvalue(), encoding)
