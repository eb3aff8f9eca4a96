"""The inputs and outputs of the commands: source files (folders searched for them) and
standard input, diagnostics on standard output or error, `.ilc` bytes, files written
atomically, and source files written back in their own encoding or shown as a diff."""

from __future__ import annotations

import errno
import os
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING

from rl1.compiler.files import SourceError, TooLargeError, read_bounded, write_atomically
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
    EXIT_USAGE,
    ColorChoice,
    FileDiagnostics,
    Format,
    diagnostic_blocks,
    exit_status,
    use_color,
    write_report,
)

from .command import Failure, message_line

if TYPE_CHECKING:  # the .ilc module loads only when an .ilc file is read
    from rl1.vm.ilc import IlcFormatError

STDIN_NAME = "<stdin>"
SOURCE_SUFFIX = ".rob"  # in any case: DOS wrote SAMPLE.ROB
MAX_ILC_BYTES = 16 * 1024 * 1024  # far more than any .ilc file holds
# How a text file rl1c writes (.ils, a picture) holds a path that is not UTF-8: each byte
# escaped as standard output and error show it (`\udcff`), where encoding it failed.
PATH_ESCAPES = "backslashreplace"


def read_input(name: str, role: str = "source file") -> Source | FileDiagnostics:
    """The source file `name` (`-` is standard input), or the E0100 report of why it
    cannot be read; `role` names it there."""
    try:
        if name != "-":
            return read_source(name)
        data = read_stdin(MAX_SOURCE_BYTES)
        if len(data) > MAX_SOURCE_BYTES:
            raise SourceError(STDIN_NAME, f"it holds more than {MAX_SOURCE_BYTES} bytes",
                              "RL/I sources are limited to that size")
        return decode(data, STDIN_NAME)
    except SourceError as error:
        return unreadable(STDIN_NAME if name == "-" else name, error, role)


def read_stdin(limit: int) -> bytes:
    """Standard input, up to `limit` bytes and one more (to tell a larger input); a
    SourceError when it cannot be read."""
    try:
        return sys.stdin.buffer.read(limit + 1)
    except OSError as error:
        raise SourceError(STDIN_NAME, stdin_problem(error), "give a file's name, or send "
                          "the input through a pipe or `< FILE`") from None


def stdin_problem(error: OSError) -> str:
    """Why standard input could not be read, as a clause: main.py holds a closed one
    (`<&-`) as a descriptor that cannot be read."""
    return "standard input is closed" if error.errno == errno.EBADF else os_reason(error)


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
            found.append(file_problem(folder, cannot("list", "folder", folder,
                                                     os_reason(error)),
                                      "check its permissions"))
        if len(found) == before:
            print(message_line(f"rl1c {command}", "warning",
                               f"no {SOURCE_SUFFIX} file under `{name}`"), file=sys.stderr)
    return found


# Every problem with a file, whatever the command and whatever the file's role, is an
# E0100 diagnostic that names the role: "cannot read the sensor script `s.json`: ...".


def cannot(verb: str, role: str, name: str, reason: str, purpose: str = "") -> str:
    """`cannot read the sensor script `s.json`: permission denied`; `purpose` says what
    for, after the name ("to make its fixes")."""
    return f"cannot {verb} the {role} `{name}`{' ' + purpose if purpose else ''}: {reason}"


def os_reason(error: OSError) -> str:
    """Why an OS call failed, as a clause: "permission denied"."""
    reason = str(error.strerror or error)
    return reason[:1].lower() + reason[1:]


def file_problem(name: str, message: str, help: str = "",
                 line: int | None = None) -> FileDiagnostics:
    """The E0100 report of a file or folder that cannot be read, written or used: of the
    file as a whole, or of its `line` (`--> s.json:3`; render.FileDiagnostics)."""
    place = Span(1, 1, 1, 1) if line is None else Span(line, 0, line, 0)
    problem = Diagnostic("E0100", Severity.ERROR, message, place, help=help or None)
    return FileDiagnostics(name, None, [problem])


def unreadable(name: str, error: SourceError, role: str) -> FileDiagnostics:
    """The E0100 report of the `role` file `name` that `error` could not read."""
    return file_problem(name, cannot("read", role, name, error.reason), error.help)


def problem_text(problem: FileDiagnostics) -> str:
    """`problem` as the checker prints a diagnostic on standard error, without a final
    newline."""
    return diagnostic_blocks(problem, color=use_color("auto", sys.stderr)).rstrip("\n")


def file_failure(problem: FileDiagnostics, status: int = EXIT_USAGE) -> Failure:
    """A Failure that prints `problem` as the checker prints a diagnostic."""
    return Failure(problem_text(problem), status)


def read_failure(error: SourceError, role: str) -> Failure:
    """The Failure of the `role` file that `error` could not read (exit status 2)."""
    return file_failure(unreadable(error.path, error, role))


def config_problem(role: str, name: str, error: Exception, help: str) -> FileDiagnostics:
    """The E0100 report of the configuration file `name` (a sensor script, a world file,
    rl1.toml, a test file) that `error` refuses: a vm.config.ConfigError, or an error it
    caused, which says where, on the `--> s.json:3` line that names the file, and what."""
    from rl1.vm.config import ConfigError

    cause = error if isinstance(error, ConfigError) else error.__cause__
    if not isinstance(cause, ConfigError) or cause.file != name:
        return file_problem(name, f"the {role} `{name}` is not valid: {error}", help)
    return file_problem(name, f"the {role} is not valid: {cause.problem}", help, cause.line)


def invalid_config(role: str, name: str, error: Exception, help: str) -> Failure:
    """The Failure (exit status 2) of the configuration file `name` that `error`
    refuses, as `config_problem` says it."""
    return file_failure(config_problem(role, name, error, help))


def invalid_file(role: str, name: str, detail: str, help: str = "",
                 status: int = EXIT_USAGE) -> Failure:
    """The Failure of the `role` file `name` that was read but is not what it must be."""
    return file_failure(file_problem(name, f"the {role} `{name}` is not valid: {detail}",
                                     help), status)


def emit(files: list[FileDiagnostics], output_format: Format, color: ColorChoice,
         action: str | None, *, err: bool = False) -> int:
    """Print the diagnostics of `files` on standard output (`err`: standard error),
    each file closed by a line that says it could not `action` (None: no such line,
    the command prints its own summary); the exit status they call for."""
    stream = sys.stderr if err else sys.stdout
    colored = output_format == "human" and use_color(color, stream)
    write_report(stream, files, output_format, color=colored, action=action)
    return exit_status(files)


def write_stdout_bytes(data: bytes) -> None:
    sys.stdout.flush()  # what was printed as text comes first
    sys.stdout.buffer.write(data)
    sys.stdout.buffer.flush()


def write_file(target: str, data: bytes, *, force: bool = False,
               role: str = "output file") -> None:
    """Writes `target` as files.write_atomically does (a read-only file only with
    `force`); a Failure (exit status 2) saying why it cannot be."""
    try:
        write_atomically(target, data, force=force)
    except OSError as error:
        raise file_failure(cannot_write(target, role, error)) from None


def cannot_write(target: str, role: str, error: OSError, purpose: str = "") -> FileDiagnostics:
    """The E0100 report of the `role` file `target` that `error` kept from being written
    (`purpose`: what for, as "to make its fixes")."""
    reason = os_reason(error)
    help = ("" if "--force" in reason else
            write_help(error, "check that its folder exists and is writable, or write "
                              "elsewhere"))
    return file_problem(target, cannot("write", role, target, reason, purpose), help)


def write_help(error: OSError, usual: str) -> str:
    """What to do when `error` kept a file from being written: `usual`, unless the disk
    is full or read-only, which no folder's permissions change."""
    match error.errno:
        case errno.ENOSPC | errno.EDQUOT:
            return "free some space on its disk, or write elsewhere"
        case errno.EROFS:
            return "its file system is read-only: write elsewhere"
    return usual


ILC_ROLE = "intermediate code file"


def read_ilc(file: str) -> bytes:
    """The bytes of an .ilc file (`-` is standard input); a Failure with exit status 2
    when it cannot be read, 1 when it is too large to be one (without reading a huge
    file whole)."""
    name = STDIN_NAME if file == "-" else file
    data: bytes | None
    try:
        if file == "-":
            data = read_stdin(MAX_ILC_BYTES)
        else:
            data = read_bounded(file, MAX_ILC_BYTES, "an .ilc file")
    except TooLargeError:
        data = None
    except SourceError as error:
        raise read_failure(error, ILC_ROLE) from None
    if data is None or len(data) > MAX_ILC_BYTES:
        raise invalid_file(ILC_ROLE, name, f"it is larger than {MAX_ILC_BYTES} bytes",
                           "check that this is the .ilc file you meant", EXIT_ERRORS)
    return data


def refused_ilc(file: str, data: bytes, error: IlcFormatError, help: str) -> Failure:
    """The Failure (exit status 1) of the .ilc file `file` whose bytes `data` the
    verifier refused with `error`; `help` says what to do. A file that does not start
    as an .ilc file does is said to be text (RL/I source, when named so) when it is,
    with what to compile, else its first bytes are shown in hex."""
    from rl1.vm.ilc import MAGIC, wrong_start

    name = STDIN_NAME if file == "-" else file
    detail = f"byte {error.offset}: {error.message}"
    if not data:
        detail = "it is empty"
    elif not data.startswith(MAGIC):  # refused for that, or as too short to be one
        try:
            decode(data, name)
        except SourceError:
            detail = wrong_start(data)
            help = "check that this is the .ilc file you meant (`rl1c compile` writes one)"
        else:
            source = file.lower().endswith(SOURCE_SUFFIX)
            detail = f"it is {'RL/I source ' if source else ''}text, not compiled code"
            output = with_suffix(file, ".ilc") if file != "-" else "FILE.ilc"
            if output == file:  # compiling it to its own name is refused: name it as source
                renamed = with_suffix(file, SOURCE_SUFFIX)
                help = (f"if it is an RL/I program, name it {renamed} and compile that, "
                        f"`rl1c compile {renamed} -o {output}`, then give {output}")
            else:
                help = (f"{'' if source else 'if it is an RL/I program, '}compile it first, "
                        f"`rl1c compile {file} -o {output}`, then give {output}")
    return invalid_file(ILC_ROLE, name, detail, help, EXIT_ERRORS)


def with_suffix(path: str, suffix: str) -> str:
    """`path` with its extension replaced by `suffix`."""
    return os.path.splitext(path)[0] + suffix


def same_file(first: str, second: str) -> bool:
    """Whether two paths (`-` is a standard stream) name one existing file."""
    return "-" not in (first, second) and os.path.exists(first) \
        and os.path.exists(second) and os.path.samefile(first, second)


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
