"""The inputs and outputs of the commands: source files and standard input, diagnostics
on standard output or error, `.ilc` bytes, and files written atomically."""

from __future__ import annotations

import os
import sys

from rl1.compiler.files import SourceError, write_atomically
from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity
from rl1.compiler.frontend.source import MAX_SOURCE_BYTES, Source, decode, read_source
from rl1.compiler.reporting.render import (
    EXIT_ERRORS,
    ColorChoice,
    FileDiagnostics,
    Format,
    exit_status,
    report,
    use_color,
)

from .command import Failure

STDIN_NAME = "<stdin>"
MAX_ILC_BYTES = 16 * 1024 * 1024  # far more than any .ilc file holds


def read_input(name: str) -> Source | FileDiagnostics:
    """The source file `name` (`-` is standard input), or the E0100 report of why it
    cannot be read."""
    try:
        if name != "-":
            return read_source(name)
        data = sys.stdin.buffer.read(MAX_SOURCE_BYTES + 1)
        if len(data) > MAX_SOURCE_BYTES:
            raise SourceError(f"{STDIN_NAME} holds more than {MAX_SOURCE_BYTES} bytes; "
                              "RL/I sources are limited to that size")
        return decode(data, STDIN_NAME)
    except SourceError as error:
        unreadable = Diagnostic("E0100", Severity.ERROR, str(error), Span(1, 1, 1, 1))
        return FileDiagnostics(STDIN_NAME if name == "-" else name, None, [unreadable])


def emit(files: list[FileDiagnostics], output_format: Format, color: ColorChoice,
         action: str, *, err: bool = False) -> int:
    """Print the diagnostics of `files` on standard output (`err`: standard error);
    the exit status they call for."""
    stream = sys.stderr if err else sys.stdout
    colored = output_format == "human" and use_color(color, stream)
    stream.write(report(files, output_format, color=colored, action=action))
    return exit_status(files)


def write_stdout_bytes(data: bytes) -> None:
    sys.stdout.flush()  # what was printed as text comes first
    sys.stdout.buffer.write(data)
    sys.stdout.buffer.flush()


def write_file(target: str, data: bytes, *, force: bool = False) -> None:
    """Writes `target` as files.write_atomically does (a read-only file only with
    `force`); a Failure (exit status 2) saying why it cannot be."""
    try:
        write_atomically(target, data, force=force)
    except OSError as error:
        raise Failure(f"error: cannot write `{target}`: {error.strerror or error}") from None


def read_ilc(file: str) -> bytes:
    """The bytes of an .ilc file (`-` is standard input); a Failure with exit status 2
    when it cannot be read, 1 when it is too large to be one (without reading a huge
    file whole)."""
    name = STDIN_NAME if file == "-" else file
    try:
        if file == "-":
            data = sys.stdin.buffer.read(MAX_ILC_BYTES + 1)
        else:
            with open(file, "rb") as stream:
                data = stream.read(MAX_ILC_BYTES + 1)
    except OSError as error:
        raise Failure(f"error: cannot read `{name}`: {error.strerror or error}") from None
    if len(data) > MAX_ILC_BYTES:
        raise Failure(f"error: `{name}` is larger than {MAX_ILC_BYTES} bytes: not an .ilc "
                      "file", EXIT_ERRORS)
    return data


def with_suffix(path: str, suffix: str) -> str:
    """`path` with its extension replaced by `suffix`."""
    return os.path.splitext(path)[0] + suffix


def same_file(first: str, second: str) -> bool:
    """Whether two paths (`-` is a standard stream) name one existing file."""
    return "-" not in (first, second) and os.path.exists(second) \
        and os.path.samefile(first, second)
