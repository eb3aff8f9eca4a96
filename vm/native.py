"""The C VM of the firmware (vm/c/) driven from Python, through ctypes: `rl1c run --engine
c`, and the differential tests that hold it to the reference VM (machine.py).

ctypes rather than cffi: it is in the standard library, so the only build step is the
shared library, which `library()` compiles on first use with the machine's C compiler
(cc, gcc or clang, or $CC) from the checkout's vm/c and spec/rl1_hardware.h, into a
private cache folder keyed by the sources' digest, and loads again only while its bytes
keep the digest recorded at its build; no make, no Python headers, nothing installed.

`NativeMachine` has Machine's stepping interface (`step`, `run`, `executed`, `state`,
`result`) over a `hardware.Hardware`, so that drive.py steps either. The C VM calls the
hardware's callbacks through function pointers; lost lines go through the C VM's own
mailbox, kept equal to the hardware's `pending` event at every crossing (a step's start
and each callback): an event the device holds is posted, an event the VM took is taken
from the device. Faults get the reference VM's messages, from the fault's kind, the
instruction at `pc` and what the callbacks answered.
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import hashlib
import os
import shlex
import shutil
import stat
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from . import isa
from .device import DeviceError, FormKey, Outcome, checked, form_name
from .faults import (
    ABORTED_MESSAGE,
    STOP_FAILED,
    Fault,
    FaultKind,
    RunResult,
    argument_range_message,
    budget_message,
    missing_handler_message,
)
from .hardware import Answer, Hardware, Status, refusal
from .language import VARIABLES, lost_line_handler
from .machine import SLICE, State

C_FOLDER = Path(__file__).resolve().parent / "c"
HEADER_FOLDER = Path(__file__).resolve().parent.parent / "spec"
SOURCES = (C_FOLDER / "rl1vm.c", C_FOLDER / "rl1vm_load.c", C_FOLDER / "test" / "ffi.c")
HEADERS = (C_FOLDER / "rl1vm.h", HEADER_FOLDER / "rl1_hardware.h")
# RL1_EXECUTED_IN_CALLS: vm->executed current inside a callback, which the simulator's
# clock reads (drive_clocked); firmware builds leave it out (vm/c/README.md).
FLAGS = ("-std=c99", "-O2", "-shared", "-fPIC", "-DRL1_EXECUTED_IN_CALLS=1")
SANITIZE = ("-fsanitize=undefined", "-fno-sanitize-recover=all")
NO_PC = 0xFFFF
MOV, MVI = 0, 1  # RL1_MOV, RL1_MVI


class BuildError(Exception):
    """The C VM's shared library cannot be built here; the message says why and what
    to do."""


class _Unusable(Exception):
    """A build cache folder this process must not, or cannot, use; the message says why."""


CACHE_LIMIT = 64 * 2**20  # bytes of a cached library read to check it (ours: about 60 KB)
DIGEST_SUFFIX = ".sha256"  # beside each library: the SHA-256 of its bytes, from its build
_ready: dict[Path, Path] = {}  # a build cache folder and key -> the library checked there
_temporary: list[str] = []  # folders of this process's temporary builds, removed at exit


def _warn(message: str) -> None:
    print(f"rl1: warning: {message}", file=sys.stderr)


def _given_compiler() -> tuple[str, ...]:
    """$CC as words (`CC="gcc -m32"` is a compiler and its arguments), () when unset."""
    given = os.environ.get("CC", "")
    try:
        return tuple(shlex.split(given))
    except ValueError as error:
        raise BuildError(f"CC={given!r} is not a command line ({error}); set CC to a C "
                         "compiler and its arguments, quoted as in a shell, or unset it"
                         ) from None


def _compiler(given: tuple[str, ...]) -> tuple[str, ...]:
    if given:
        if shutil.which(given[0]) is None:
            raise BuildError(f"CC={shlex.join(given)!r} names {given[0]!r}, which is no "
                             "command here; set CC to a C compiler, or unset it to use cc, "
                             "gcc or clang")
        return given
    for name in ("cc", "gcc", "clang"):
        if shutil.which(name):
            return (name,)
    raise BuildError("the C engine needs a C compiler to build vm/c, and this machine has "
                     "none (cc, gcc or clang, or $CC); install one (Debian: apt-get install "
                     "gcc), or run with --engine vm")


def _cache() -> Path | None:
    """$XDG_CACHE_HOME/rl1, or ~/.cache/rl1; a relative XDG_CACHE_HOME is ignored, as the
    XDG Base Directory specification says. None when there is no home to hold it."""
    base = os.environ.get("XDG_CACHE_HOME", "")
    if os.path.isabs(base):
        return Path(base) / "rl1"
    try:
        return Path.home() / ".cache" / "rl1"
    except (RuntimeError, KeyError):  # no $HOME, and no entry in the password database
        return None


def library(folder: Path | None = None, sanitize: bool = False,
            warn: Callable[[str], None] = _warn) -> Path:
    """The shared library of the C VM, built into `folder` (default: the user's cache,
    ~/.cache/rl1) unless a build of the same sources, flags and $CC is there and intact.
    With `sanitize`, undefined behaviour aborts the process (for the tests).

    Whatever is in a cache may have been damaged (a full disk, a restored CI cache) or
    planted, and loading a library runs its code, so: the folder must be this user's
    and writable by no one else (a missing one is made owner-only); a library is written
    whole under another name and renamed, with the SHA-256 of its bytes beside it; and a
    library found there is used only when its bytes have that digest (checked before
    anything loads it), and built again, with a warning, when not. A cache folder that
    cannot be used gets a warning and a build into a private temporary folder instead."""
    missing = [str(path) for path in (*SOURCES, *HEADERS) if not path.is_file()]
    if missing:
        raise BuildError("the C engine builds vm/c from a checkout of rl1, and these files "
                         f"are missing: {', '.join(missing)}")
    given = _given_compiler()
    flags = (*FLAGS, *(SANITIZE if sanitize else ()))
    key = hashlib.sha256("\0".join((*given, "", *flags)).encode())
    for path in (*SOURCES, *HEADERS):
        key.update(path.read_bytes())
    name = f"librl1vm-{key.hexdigest()[:16]}.so"
    cache = folder or _cache()
    where = Path(os.path.abspath(cache or tempfile.gettempdir())) / name
    if where in _ready:  # built or checked already by this process
        return _ready[where]
    try:
        if cache is None:
            raise _Unusable("there is no home folder (set HOME or XDG_CACHE_HOME)")
        target = _private(cache) / name
        if _intact(target):
            _ready[where] = target
            return target
        if os.path.lexists(target):
            warn(f"the C VM's library in the build cache, {target}, is damaged or was not "
                 "built there (its bytes do not have the digest recorded when it was "
                 "built); building it again")
        built = _build(target, given, flags)
    except (_Unusable, OSError) as error:
        reason = (f"it cannot be written: {error.strerror or error}"
                  if isinstance(error, OSError) else str(error))
        warn(f"cannot use {cache} as the C VM's build cache ({reason}); building the "
             "C VM in a temporary folder, again on each run until XDG_CACHE_HOME names a "
             "folder of your own")
        built = _temporary_build(name, given, flags)
    _ready[where] = built
    return built


def _private(folder: Path) -> Path:
    """`folder`, made owner-only if missing; _Unusable when it is no folder of this
    user's alone (another user owns it, or others may write to it)."""
    try:
        folder.parent.mkdir(parents=True, exist_ok=True)
        with contextlib.suppress(FileExistsError):
            folder.mkdir(mode=0o700)
        status = folder.stat()  # a symbolic link is judged by what it leads to
    except FileExistsError:
        raise _Unusable(f"{folder.parent} is not a folder") from None
    except OSError as error:
        raise _Unusable(f"it cannot be made: {error.strerror or error}") from None
    if not stat.S_ISDIR(status.st_mode):
        raise _Unusable("it is not a folder")
    if status.st_uid != os.getuid():
        raise _Unusable(f"user {status.st_uid} owns it, not you")
    if status.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        raise _Unusable(f"other users may write to it (chmod go-w {shlex.quote(str(folder))} "
                        "makes it yours alone)")
    return folder


def _intact(target: Path) -> bool:
    """`target` is a regular file whose bytes have the digest recorded beside it."""
    recorded = _bytes_of(target.with_name(target.name + DIGEST_SUFFIX), 128)
    data = _bytes_of(target, CACHE_LIMIT)
    return (recorded is not None and data is not None
            and recorded.decode("ascii", "replace").strip() == hashlib.sha256(data).hexdigest())


def _bytes_of(path: Path, limit: int) -> bytes | None:
    """The bytes of the regular file `path` (never a link, a FIFO or a device, which
    could block), or None when it is none or larger than `limit`."""
    try:
        status = os.lstat(path)
        if not stat.S_ISREG(status.st_mode) or status.st_size > limit:
            return None
        with open(path, "rb") as stream:
            return stream.read(limit + 1)
    except OSError:
        return None


def _temporary_build(name: str, given: tuple[str, ...], flags: tuple[str, ...]) -> Path:
    """The library built into a new private temporary folder, removed at exit."""
    try:
        folder = tempfile.mkdtemp(prefix="rl1-vm-")  # owner-only
    except OSError as error:
        raise BuildError(f"no folder to build the C VM in: the cache cannot be used, nor "
                         f"the temporary folder ({error.strerror or error}); set "
                         "XDG_CACHE_HOME or TMPDIR to a folder of your own") from None
    _temporary.append(folder)
    return _build(Path(folder) / name, given, flags)


@atexit.register
def _remove_temporary_builds() -> None:
    for folder in _temporary:
        shutil.rmtree(folder, ignore_errors=True)


def _build(target: Path, given: tuple[str, ...], flags: tuple[str, ...]) -> Path:
    """Compile the library to `target`, and its digest beside it. Built under another
    name, then renamed: no one ever sees half a file; the digest goes last, so a library
    without its digest (a build cut short) is built again."""
    compiler = _compiler(given)
    with tempfile.TemporaryDirectory(dir=target.parent) as scratch:
        built = Path(scratch) / target.name
        command = [*compiler, *flags, f"-I{HEADER_FOLDER}", "-o", str(built),
                   *map(str, SOURCES)]
        process = subprocess.run(command, capture_output=True, text=True, check=False)
        if process.returncode != 0:
            raise BuildError(f"{compiler[0]} could not build the C VM ({shlex.join(command)}):"
                             f"\n{process.stderr.strip()}")
        digest = built.with_name(built.name + DIGEST_SUFFIX)
        digest.write_text(hashlib.sha256(built.read_bytes()).hexdigest() + "\n",
                          encoding="ascii")
        for path in (built, digest):
            with open(path, "rb") as stream:
                os.fsync(stream.fileno())
        built.replace(target)
        digest.replace(target.with_name(digest.name))
    return target


# The C structures of spec/rl1_hardware.h, mirrored (checked against rl1_ffi_layout).

class _Reading(ctypes.Structure):
    _fields_ = [("result", ctypes.c_int16), ("writes", ctypes.c_int16 * 4)]


if TYPE_CHECKING:  # what the callbacks get, as typeshed spells it
    _Args = ctypes._Pointer[ctypes.c_int16]
    _Out = ctypes._Pointer[_Reading]
_ARGS = ctypes.POINTER(ctypes.c_int16)
_OUT = ctypes.POINTER(_Reading)
_BEGIN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p)
_CALL = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint8, _ARGS, _OUT)
_START = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint8, _ARGS)
_POLL = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, _OUT)


class _Hardware(ctypes.Structure):
    _fields_ = [("ctx", ctypes.c_void_p), ("begin", _BEGIN), ("call", _CALL),
                ("start", _START), ("poll", _POLL), ("stop", _BEGIN), ("end", _BEGIN)]


class _Mailbox(ctypes.Structure):
    _fields_ = [("event", ctypes.c_uint8), ("posted", ctypes.c_uint8),
                ("taken", ctypes.c_uint8)]


class _Vm(ctypes.Structure):
    _fields_ = [("V", ctypes.c_int16 * len(VARIABLES)), ("acc", ctypes.c_int16),
                ("R", ctypes.c_int16), ("pc", ctypes.c_uint16),
                ("executed", ctypes.c_uint32), ("budget", ctypes.c_uint32),
                ("mailbox", _Mailbox), ("waiting", ctypes.c_uint8),
                ("state", ctypes.c_uint8), ("fault", ctypes.c_uint8),
                ("begun", ctypes.c_uint8), ("stop_failed", ctypes.c_uint8)]


class _Program(ctypes.Structure):  # vm/c/rl1vm.h; only the C side reads its fields
    _fields_ = [("code", ctypes.c_void_p), ("lines", ctypes.c_void_p),
                ("source_name", ctypes.c_void_p), ("digest", ctypes.c_void_p),
                ("code_size", ctypes.c_uint16), ("handlers", ctypes.c_uint16 * 4),
                ("features", ctypes.c_uint16), ("flags", ctypes.c_uint16),
                ("line_count", ctypes.c_uint16), ("source_name_size", ctypes.c_uint8),
                ("minor", ctypes.c_uint8)]


_LAYOUT = (ctypes.sizeof(_Vm), _Vm.mailbox.offset, _Vm.pc.offset, _Vm.executed.offset,
           _Vm.state.offset, _Vm.fault.offset, _Vm.stop_failed.offset,
           ctypes.sizeof(_Hardware), ctypes.sizeof(_Reading), ctypes.sizeof(_Program))

_FAULTS = {kind.exit_status: kind for kind in FaultKind}
_STATUS = {Status.OK: 0, Status.BUSY: 1, Status.ERROR: 2}
_libraries: dict[Path, ctypes.CDLL] = {}

F = TypeVar("F", bound=Callable[..., int])


def load(path: Path) -> ctypes.CDLL:
    """The library at `path` (library()), its functions typed, its layout checked."""
    if path in _libraries:
        return _libraries[path]
    try:
        lib = ctypes.CDLL(str(path))
    except OSError as error:  # such as a library for another machine (CC="gcc -m32")
        raise BuildError(f"cannot load the C VM's library {path}: {error}; if $CC builds "
                         "for another machine, set CC to a compiler for this one") from None
    lib.rl1_ffi_layout.argtypes = [ctypes.POINTER(ctypes.c_uint32)]
    lib.rl1_ffi_start.argtypes = [ctypes.POINTER(_Vm), ctypes.POINTER(_Program),
                                  ctypes.c_char_p, ctypes.c_uint32, ctypes.c_uint32,
                                  ctypes.POINTER(ctypes.c_uint32)]
    lib.rl1_ffi_post.argtypes = [ctypes.POINTER(_Vm), ctypes.c_uint8, ctypes.c_uint8]
    lib.rl1_ffi_abort.argtypes = [ctypes.POINTER(_Vm)]
    lib.rl1_ffi_abort.restype = None
    lib.rl1_step.argtypes = [ctypes.POINTER(_Vm), ctypes.POINTER(_Program),
                             ctypes.POINTER(_Hardware), ctypes.c_uint32]
    lib.rl1_line_at.argtypes = [ctypes.POINTER(_Program), ctypes.c_uint16]
    lib.rl1_line_at.restype = ctypes.c_uint16
    lib.rl1_test_load.argtypes = [ctypes.c_char_p, ctypes.c_uint32, ctypes.c_size_t,
                                  ctypes.POINTER(ctypes.c_uint32)]
    layout = (ctypes.c_uint32 * len(_LAYOUT))()
    lib.rl1_ffi_layout(layout)
    if tuple(layout) != _LAYOUT:
        raise BuildError(f"the C VM's structures are not laid out as rl1.vm.native mirrors "
                         f"them: {tuple(layout)} != {_LAYOUT}")
    _libraries[path] = lib
    return lib


class NativeMachine:
    """One run of the .ilc file `data` on the C VM, driving `hardware`; the C loader
    must accept the file (verify it in Python first for a readable refusal)."""

    def __init__(self, data: bytes, hardware: Hardware, budget: int, lib: ctypes.CDLL) -> None:
        self.hardware = hardware
        self.lib = lib
        self._file = ctypes.create_string_buffer(data, len(data))  # the VM reads it in place
        self._size = len(data)
        self._vm = _Vm()
        self._program = _Program()  # points into self._file
        self._error: BaseException | None = None  # raised in a callback, raised again
        self._posted = False  # the hardware's pending event is in the mailbox
        self._message = ""  # why the device failed, for the fault's message
        self._stop_message: str | None = None
        self._form: FormKey | None = None  # the started built-in
        self._stepping = False  # inside rl1_step: a step now comes from a callback
        self._callbacks = _Hardware(None, _BEGIN(self._guard(self._begin)),
                                    _CALL(self._guard(self._call)),
                                    _START(self._guard(self._start)),
                                    _POLL(self._guard(self._poll)),
                                    _BEGIN(self._guard(self._stop)),
                                    _BEGIN(self._guard(self._end)))
        where = ctypes.c_uint32(0)
        refusal = lib.rl1_ffi_start(ctypes.byref(self._vm), ctypes.byref(self._program),
                                    self._file, self._size, budget, ctypes.byref(where))
        if refusal:
            raise ValueError(f"the C loader refuses the file (refusal {refusal} at file "
                             f"offset {where.value}), which the caller was to verify")
        self.budget = budget
        self.result: RunResult | None = None

    # The stepping interface of machine.Machine

    @property
    def executed(self) -> int:
        return int(self._vm.executed)

    @executed.setter
    def executed(self, count: int) -> None:
        """Set back between steps, as firmware tops up a patrol's budget (vm/c/README.md)."""
        self._vm.executed = count

    @property
    def state(self) -> State:
        return State(self._vm.state)

    @property
    def variables(self) -> tuple[int, ...]:
        return tuple(self._vm.V)

    def current_line(self) -> int | None:
        """The source line of the call under way, or of the instruction run last between
        steps (as Machine.current_line): the line entry at or before the byte before pc;
        None before the first instruction, or without a line map."""
        pc = int(self._vm.pc)
        if pc in (0, NO_PC):  # before the first instruction, or a fault there
            return None
        line = int(self.lib.rl1_line_at(ctypes.byref(self._program), pc - 1))
        return line or None

    def step(self, limit: int) -> State:
        """Run at most `limit` instructions and say where the run stands. From one of
        its own callbacks, the C VM refuses the step, and the step under way faults."""
        if self._stepping:
            self._message = ("a callback stepped the VM that called it, which the C VM "
                             "refuses (spec/rl1_hardware.h, rl1_step)")
            return self._rl1_step(limit)
        self._sync()
        self._stepping = True
        try:
            state = self._rl1_step(limit)
        finally:
            self._stepping = False
        if self._error is not None:
            error, self._error = self._error, None
            raise error
        self._sync()
        if state in (State.ENDED, State.FAULTED) and self.result is None:
            self.result = RunResult(tuple(self._vm.V), self._fault())
        return state

    def _rl1_step(self, limit: int) -> State:
        return State(self.lib.rl1_step(ctypes.byref(self._vm), ctypes.byref(self._program),
                                       ctypes.byref(self._callbacks), limit))

    def abort(self) -> None:
        """The emergency stop, as Machine.abort: rl1_abort on the VM's mailbox (from a
        callback too, as an interrupt handler would)."""
        self.lib.rl1_ffi_abort(ctypes.byref(self._vm))

    def run(self) -> RunResult:
        while self.step(SLICE) in (State.RUNNING, State.WAITING):
            pass
        assert self.result is not None
        return self.result

    # Lost lines: the mailbox and the hardware's pending event kept equal

    def _sync(self) -> None:
        box = self._vm.mailbox
        if self._posted and box.posted == box.taken:  # the VM took it
            self._posted = False
            self.hardware.take_event()
        event = self.hardware.pending
        if event is not None and not self._posted:
            self.lib.rl1_ffi_post(ctypes.byref(self._vm), event.mode,
                                  MOV if event.command == "MOV" else MVI)
            self._posted = True

    # The callbacks

    def _guard(self, callback: F) -> F:
        """`callback` synchronizing the mailbox around it, and keeping an exception to
        raise after the step (ctypes would print it and answer 0)."""
        def guarded(*args: object) -> int:
            try:
                self._sync()
                status = callback(*args)
                self._sync()
                return status
            except BaseException as error:  # raised again by step()
                self._error = self._error or error
                return _STATUS[Status.ERROR]
        return guarded  # type: ignore[return-value]

    def _answer(self, answer: Answer, form: FormKey | None, out: _Out | None,
                polled: bool = False) -> int:
        """A callback's status; an ERROR's message kept; what a finished call read put in
        `out` (a value that is no 16-bit integer is the device's error, as machine.py's
        device.checked says, and so is one outside its range, which the C VM finds)."""
        if answer.status is Status.OK and form is not None and out is not None:
            try:
                checked(form, answer.outcome)
            except DeviceError as error:
                self._message = str(error)
                if not all(-0x8000 <= value <= 0x7FFF for value in _values(answer.outcome)):
                    return _STATUS[Status.ERROR]
            _fill(out.contents, answer.outcome)
        if answer.status is Status.ERROR or (answer.status is Status.BUSY and not polled):
            self._message = refusal(answer)
        return _STATUS[answer.status]

    def _begin(self, _ctx: object) -> int:
        return self._answer(self.hardware.begin(), None, None)

    def _call(self, _ctx: object, opcode: int, args: _Args, out: _Out) -> int:
        form, values = _decode_call(opcode, args)
        return self._answer(self.hardware.call(form, values), form, out)

    def _start(self, _ctx: object, opcode: int, args: _Args) -> int:
        form, values = _decode_call(opcode, args)
        self._form = form
        return self._answer(self.hardware.start(form, values), None, None)

    def _poll(self, _ctx: object, out: _Out) -> int:
        return self._answer(self.hardware.poll(), self._form, out, polled=True)

    def _stop(self, _ctx: object) -> int:
        answer = self.hardware.stop()
        self._stop_message = refusal(answer) if answer.status is not Status.OK else None
        return _STATUS[answer.status]

    def _end(self, _ctx: object) -> int:
        answer = self.hardware.end()
        if self._vm.fault:  # after a fault (set before its stop and end): its message stays
            return _STATUS[answer.status]
        return self._answer(answer, None, None)

    # The fault, told as the reference VM tells it

    def _fault(self) -> Fault | None:
        vm = self._vm
        kind = _FAULTS.get(vm.fault)
        if kind is None:
            return None
        at = int(vm.pc)
        line = None if at == NO_PC else (
            self.lib.rl1_line_at(ctypes.byref(self._program), at) or None)
        message = self._message
        if kind is FaultKind.BUDGET:
            message = budget_message(self.budget)
        elif kind is FaultKind.ABORTED:
            message = ABORTED_MESSAGE
        elif kind is FaultKind.ARGUMENT_RANGE:
            message = self._range_message(at)
        elif kind is FaultKind.MISSING_HANDLER:
            event = int(vm.mailbox.event)
            mode, command = event >> 1, "MVI" if event & 1 else "MOV"
            label = lost_line_handler(mode, command)
            assert label is not None
            message = missing_handler_message(mode, command, label)
        if self._stop_message is not None:
            message += STOP_FAILED + self._stop_message
        return Fault(kind, message, line)

    def _range_message(self, at: int) -> str:
        start = int.from_bytes(self._file.raw[12:14], "little")  # header_size
        size = int.from_bytes(self._file.raw[14:16], "little")  # code_size
        instruction = isa.decode_at(self._file.raw[start:start + size], at)
        form = instruction.info.form
        assert form is not None and instruction.info.builtin is not None
        for param, arg in zip(form.params, instruction.args, strict=True):
            value = int(self._vm.V[arg.value]) if arg.is_var else arg.value
            if arg.is_var and not param.low <= value <= param.high:
                return argument_range_message(param.name, form_name(instruction.info.builtin),
                                              value, arg.value, param.low, param.high)
        raise AssertionError("an argument-range fault with every argument in range")


def _decode_call(opcode: int, args: _Args) -> tuple[FormKey, tuple[int, ...]]:
    info = isa.OPCODES[opcode]
    assert info.builtin is not None and info.form is not None
    return info.builtin, tuple(args[k] for k in range(len(info.form.params)))


def _values(outcome: Outcome) -> tuple[int, ...]:
    return (*outcome.writes, *(() if outcome.result is None else (outcome.result,)))


def _fill(out: _Reading, outcome: Outcome) -> None:
    out.result = outcome.result or 0
    for index, value in enumerate(outcome.writes):
        out.writes[index] = value
