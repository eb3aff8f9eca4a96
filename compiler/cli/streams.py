"""The inputs and outputs of the commands: source files (folders searched for them) and
standard input, diagnostics on standard output or error, `.ilc` bytes, files written
atomically, and source files written back in their own encoding or shown as a diff."""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence

from rl1.compiler.files import SourceError, write_atomically
from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity
from rl1.compiler.frontend.source import (
    MAX_SOURCE_BYTES,
    UTF8_BOM,
    Source,
    decode,
    read_source,
    split_lines,
)
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
SOURCE_SUFFIX = ".rob"  # in any case: DOS wrote SAMPLE.ROB
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
        return unreadable(STDIN_NAME if name == "-" else name, str(error))


def source_files(names: Sequence[str], command: str) -> list[str | FileDiagnostics]:
    """The files `names` name: each file as given, and for a folder every `.rob` file
    below it (the extension in any case) in sorted order, leaving out hidden files and
    folders (`.git`), what is no regular file, and links to folders. A folder that cannot be listed
    is an E0100 report; one without a `.rob` file is said on standard error."""
    found: list[str | FileDiagnostics] = []
    for name in names:
        if name == "-" or not os.path.isdir(name):
            found.append(name)
            continue
        before = len(found)
        unlisted: list[OSError] = []
        for folder, folders, files in os.walk(name, onerror=unlisted.append):
            folders[:] = sorted(f for f in folders if not f.startswith("."))
            # Regular files only: reading a FIFO named x.rob would wait for ever.
            found += [path for path in (os.path.join(folder, file) for file in sorted(files)
                                        if file.lower().endswith(SOURCE_SUFFIX)
                                        and not file.startswith("."))
                      if os.path.isfile(path)]
        for error in unlisted:
            folder = str(error.filename or name)
            found.append(unreadable(folder, f"{folder}: cannot list this folder "
                                    f"({error.strerror or error}); check its permissions"))
        if len(found) == before:
            print(f"rl1c {command}: warning: no {SOURCE_SUFFIX} file under `{name}`",
                  file=sys.stderr)
    return found


def unreadable(name: str, message: str) -> FileDiagnostics:
    """The E0100 report of a file or folder that cannot be read."""
    problem = Diagnostic("E0100", Severity.ERROR, message, Span(1, 1, 1, 1))
    return FileDiagnostics(name, None, [problem])


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


def encode_like(source: Source, text: str, *, bom: bool) -> bytes:
    """`text` in the encoding `source` was read in. The commands that rewrite a source
    (fmt, check --fix) keep every non-ASCII character of it (they are all in comments),
    so a CP932 source's characters all have a CP932 encoding."""
    return (UTF8_BOM if bom else b"") + text.encode(source.encoding)


def write_back(source: Source, text: str, *, force: bool = False) -> None:
    """Replace the file `source` was read from with `text`, in the file's own encoding
    and with its byte-order mark if it had one, as files.write_atomically does (a
    read-only file only with `force`). OSError if that cannot be done."""
    write_atomically(source.name, encode_like(source, text, bom=source.bom), force=force)


def unified_diff(name: str, before: str, after: str, change: str) -> str:
    """What a command would change in file `name`, as a unified diff (line ends shown as
    LF); `change` names the new side: `x.rob (formatted)`."""
    import difflib  # only for a diff: 2 ms of every start

    return "".join(difflib.unified_diff(
        [line + "\n" for line in split_lines(before)],
        [line + "\n" for line in split_lines(after)],
        fromfile=name, tofile=f"{name} ({change})",
    ))
