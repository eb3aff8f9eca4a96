"""`rl1c(*args)`: runs the `rl1c` command line in the test process with click's
CliRunner, as a terminal-less shell would, and returns what it printed and its exit
status."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from click.testing import CliRunner

from rl1.compiler.cli.main import rl1c as command


@dataclass(frozen=True)
class Result:
    """What a run printed, as bytes and decoded exactly (click's own Result turns CRLF
    into LF in its text, which would hide a stray carriage return)."""

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


def rl1c(*args: str | Path, stdin: bytes = b"", encoding: str = "utf-8",
         env: dict[str, str | None] | None = None) -> Result:
    """Runs `rl1c args...` reading `stdin`, with standard streams in `encoding` and the
    environment variables `env` set (None: unset) for the run."""
    # rl1c reports every failure itself; an exception escaping it is a bug to see whole.
    runner = CliRunner(charset=encoding, catch_exceptions=False)
    result = runner.invoke(command, [str(arg) for arg in args], input=stdin, env=env)
    return Result(result.exit_code, result.stdout_bytes, result.stderr_bytes,
                  result.output_bytes, encoding)


def without_progress(stderr: str) -> list[str]:
    """The lines of a campaign's standard error but its progress lines (`fuzz: ...`,
    every 10 s, so that a loaded machine prints more of them), which a test that
    compares the warnings exactly leaves out."""
    return [line for line in stderr.splitlines() if not line.startswith("fuzz: ")]
