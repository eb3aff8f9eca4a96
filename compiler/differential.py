"""Differential runs: one program and sensor script on several engines, and what differs.

spec/optimization.md is the contract: section 2 says what is observable (the device
trace, how the run ends, the 53 variables), section 3 the budget invariant between
optimization levels, section 5 the engines (`ast`, `vm-O0`..`vm-O2`, `c-O0`..`c-O2`,
`exec:COMMAND`, `exec-ON:COMMAND`). `rl1c fuzz` and the property tests both compare runs
through this module. The C VM of the firmware (vm/c/, through vm/native.py) is one more `Engine`: a
name and a `run`.
"""

from __future__ import annotations

import atexit
import base64
import contextlib
import json
import os
import pickle
import re
import selectors
import shlex
import signal
import subprocess
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, Protocol

from rl1.compiler.analysis import analyze
from rl1.compiler.backend.driver import OPTIMIZATION_LEVELS, compile_text
from rl1.compiler.executors import (
    exit_how,
    ignore_interrupts,
    orphans_ended,
    pickled_error,
    spawn,
    unpickled_error,
)
from rl1.compiler.interpreter import interpret
from rl1.compiler.strategies import Run
from rl1.vm import isa
from rl1.vm.drive import drive
from rl1.vm.faults import FaultKind
from rl1.vm.hardware import Blocking
from rl1.vm.language import VARIABLES, decimal_value
from rl1.vm.machine import Machine
from rl1.vm.native import BuildError, NativeMachine, library, load
from rl1.vm.scripted import IGNORED, ScriptedDevice, parse_script, run_document
from rl1.vm.verifier import verify

SOURCE_NAME = "fuzz.rob"
_ENTRY_KEYS = ("time", "call", "args", "result")
EXEC_TIMEOUT = 10.0  # seconds an exec: engine may take for one run
EXEC_OUTPUT_LIMIT = 16 * 2**20  # bytes it may print: a run's JSON, however long the trace
STDERR_KEPT = 4096  # the end of its standard error, for the message of a run it did not print
BUDGET_CODE = FaultKind.BUDGET.code
CRASH_CODE = "crash"  # the status of an engine that raised (a bug in it, not a run)
ENDED_CODE = "ended-process"  # the status of an engine that ended the process it ran in
ENDED = "ended its process"  # how a problem of ENDED_CODE begins, after the engine's name


@dataclass(frozen=True)
class Observation:
    """What section 2 of spec/optimization.md says a run shows, and, from the reference
    VM, the instructions executed (in all, and up to each call)."""

    document: dict[str, Any]  # as scripted.run_document gives it
    executed: int | None = None
    call_counts: tuple[int, ...] | None = None
    opcodes: dict[str, int] | None = None  # the instructions executed by opcode, if counted

    @property
    def crashed(self) -> bool:
        status = self.document.get("status")
        return isinstance(status, dict) and status.get("code") == CRASH_CODE

    @property
    def ran_away(self) -> bool:
        status = self.document.get("status")
        return isinstance(status, dict) and status.get("code") == BUDGET_CODE

    def ending(self) -> object:
        status = self.document.get("status")
        if isinstance(status, dict):
            return {"code": status.get("code"), "line": status.get("line")}
        if status == "ok":  # the status of format 1 of the protocol
            return {"code": "ok", "line": None}
        return status

    def commands(self) -> list[Any]:
        """The trace as the vectors write it (time, call, args, result: the source line
        and what a loss did are `rl1c run`'s additions), without the losses that did
        nothing, nor the stop that ends a run the watchdog stopped."""
        trace = [{key: entry[key] for key in _ENTRY_KEYS if key in entry}
                 if isinstance(entry, dict) else entry
                 for entry in self.document.get("trace", [])
                 if not (isinstance(entry, dict) and entry.get("effect") in IGNORED)]
        if self.ran_away and trace and trace[-1].get("call") == "STOP":
            trace.pop()
        return trace


class EngineUnavailable(Exception):
    """An engine cannot run on this machine at all (not a finding); the message says why
    and what to do. native.BuildError is the C engine's."""


class Engine(Protocol):
    @property
    def name(self) -> str: ...

    @property
    def level(self) -> int | None:
        """The optimization level of the code it runs; None for the interpreter, which
        runs the source and counts statements."""

    def run(self, case: Run, budget: int) -> Observation: ...


@dataclass(frozen=True)
class AstEngine:
    """The AST interpreter: the reference for what a program means."""

    name: str = "ast"
    level: None = None

    def run(self, case: Run, budget: int) -> Observation:
        device = ScriptedDevice(parse_script(case.script))
        result = interpret(analyze(case.source).program, device, budget)
        return Observation(run_document(result, device.trace))


@dataclass(frozen=True)
class VmEngine:
    """The compiler at one level, then the reference VM; `counting` the instructions
    executed by opcode too (`rl1c fuzz --format json`), which costs a little."""

    level: int
    counting: bool = field(default=False, compare=False)
    name: str = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "name", f"vm-O{self.level}")

    def run(self, case: Run, budget: int) -> Observation:
        device = ScriptedDevice(parse_script(case.script))
        # As `rl1c run` does (compiler/runner.py): the device told each call's line, the
        # run stepped by `drive`, which makes the script's losses after instruction counts.
        machine = (_CountingMachine if self.counting else Machine)(
            verify(compiled(case.source, self.level)),
            Blocking(device, lambda: machine.current_line()), budget)
        result = drive(machine, device)
        return Observation(run_document(result, device.trace), machine.executed,
                           tuple(machine.call_counts),
                           dict(machine.opcodes) if isinstance(machine, _CountingMachine)
                           else None)


class _CountingMachine(Machine):
    """The reference VM, counting the instructions it executes by opcode."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.opcodes: Counter[str] = Counter()

    def _execute(self, instruction: isa.Instruction) -> None:
        self.opcodes[instruction.info.name] += 1
        super()._execute(instruction)


@dataclass(frozen=True)
class CEngine:
    """The compiler at one level, then the C VM of the firmware (built on first use:
    native.BuildError when this machine has no C compiler)."""

    level: int
    name: str = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "name", f"c-O{self.level}")

    def run(self, case: Run, budget: int) -> Observation:
        device = ScriptedDevice(parse_script(case.script))
        machine = NativeMachine(compiled(case.source, self.level),
                                Blocking(device, lambda: machine.current_line()), budget,
                                load(library()))
        result = drive(machine, device)
        return Observation(run_document(result, device.trace), machine.executed)



@dataclass(frozen=True)
class ExecEngine:
    """A command run once per program on the file compiled at `level`
    (spec/optimization.md, section 5): `exec:COMMAND` at -O0, `exec-ON:COMMAND` at -ON."""

    command: str
    level: int = 0
    name: str = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "name", _exec_name("exec", self.level, self.command))

    def command_line(self, ilc_path: str, sensors_path: str, budget: int) -> str:
        return (self.command.replace("{ilc}", shlex.quote(ilc_path))
                .replace("{sensors}", shlex.quote(sensors_path))
                .replace("{budget}", str(budget)))

    def run(self, case: Run, budget: int) -> Observation:
        with tempfile.TemporaryDirectory(prefix="rl1-fuzz-") as folder:
            if shlex.quote(folder) != folder:
                # A quoted word is literal bare, but not inside double quotes, where a
                # `$(...)` or backquote of the path would run: the paths need no quotes.
                raise EngineUnavailable(
                    f"exec: engines get the paths of their files in a shell command, and "
                    f"the temporary folder {folder} has characters a shell reads (such as "
                    "spaces, quotes, $ or `); set TMPDIR to a folder whose path has only "
                    "letters, digits and / . _ - + , : @ % =")
            ilc_path = os.path.join(folder, "fuzz.ilc")
            sensors_path = os.path.join(folder, "fuzz.sensors.json")
            with open(ilc_path, "wb") as stream:
                stream.write(compiled(case.source, self.level))
            with open(sensors_path, "w", encoding="utf-8") as stream:
                json.dump(case.script, stream)
            with orphans_ended():  # what it started in a session of its own, too
                ran = _run_shell(self.command_line(ilc_path, sensors_path, budget))
        match ran:
            case _Ran(ending="timeout"):
                return _no_run("timeout", f"it ran longer than {EXEC_TIMEOUT:.0f} seconds")
            case _Ran(ending="too-much-output"):
                return _no_run("too-much-output", "it printed more than "
                               f"{EXEC_OUTPUT_LIMIT // 2**20} MiB on standard output")
        return Observation(printed_run(ran.stdout, ran.stderr))


@dataclass(frozen=True)
class BatchEngine:
    """A command started once (per process) that runs one program after another
    (spec/optimization.md, section 5, "Batch engines"): `exec-batch:COMMAND` given the
    file compiled with -O0, `exec-batch-ON:COMMAND` at -ON. It reads a job a line on its
    standard input and answers each with the run on a line of its standard output."""

    command: str
    level: int = 0
    name: str = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "name", _exec_name("exec-batch", self.level, self.command))

    def job(self, case: Run, budget: int) -> bytes:
        """The job line of `case` (without its line end)."""
        return json.dumps({"ilc": base64.b64encode(compiled(case.source, self.level))
                           .decode("ascii"), "sensors": case.script, "budget": budget},
                          separators=(",", ":")).encode("utf-8")

    def run(self, case: Run, budget: int) -> Observation:
        batch = _BATCHES.get(self.command)
        if batch is None or batch.owner != os.getpid():  # not one a parent process started
            batch = _BATCHES[self.command] = _Batch(self.command)
        return batch.ask(self.job(case, budget))


class _Batch:
    """A batch engine's process, started at its first job and again after one it did
    not answer as the protocol says (its state is then unknown)."""

    def __init__(self, command: str) -> None:
        self.command = command
        self.owner = os.getpid()
        self.process: subprocess.Popen[bytes] | None = None
        self.stderr = bytearray()  # the end of its standard error

    def ask(self, job: bytes) -> Observation:
        """The engine's answer to `job`, or a status saying why there is none."""
        if self.process is None:
            self.process = subprocess.Popen(self.command, shell=True, stdin=subprocess.PIPE,
                                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                            start_new_session=True)
            self.stderr.clear()
        elif self._printed_since_answering():
            return self._failed("no-run", "it printed a line after its answer to the job "
                                "before (two lines for one job)")
        process = self.process
        assert process.stdin is not None and process.stdout is not None \
            and process.stderr is not None
        unsent, answer = memoryview(job + b"\n"), bytearray()
        deadline = time.monotonic() + EXEC_TIMEOUT
        with selectors.DefaultSelector() as selector:
            os.set_blocking(process.stdin.fileno(), False)
            selector.register(process.stdin, selectors.EVENT_WRITE)
            selector.register(process.stdout, selectors.EVENT_READ, answer)
            selector.register(process.stderr, selectors.EVENT_READ, self.stderr)
            while b"\n" not in answer:
                left = deadline - time.monotonic()
                if left <= 0:
                    return self._failed("timeout", "it answered no job in "
                                        f"{EXEC_TIMEOUT:.0f} seconds")
                for key, _ in selector.select(left):
                    if key.fileobj is process.stdin:
                        try:
                            unsent = unsent[os.write(key.fd, unsent):]
                        except BrokenPipeError:
                            return self._failed("no-run", self._gone("input", "reading the job"))
                        if not unsent:
                            selector.unregister(process.stdin)
                        continue
                    chunk = os.read(key.fd, 1 << 16)
                    if not chunk and key.fileobj is process.stdout:
                        return self._failed("no-run", self._gone("output", "answering"))
                    if not chunk:
                        selector.unregister(key.fileobj)
                    key.data.extend(chunk)
                del self.stderr[:-STDERR_KEPT]
                if len(answer) > EXEC_OUTPUT_LIMIT:
                    return self._failed("too-much-output", "it printed more than "
                                        f"{EXEC_OUTPUT_LIMIT // 2**20} MiB for one job")
        line, rest = answer.split(b"\n", 1)
        if rest or unsent:
            return self._failed("no-run", "it printed more than one line for one job" if rest
                                else "it answered before it had read the whole job")
        return Observation(printed_run(bytes(line), bytes(self.stderr)))

    def _printed_since_answering(self) -> bool:
        """Whether the engine wrote on its standard output after its last answer, which
        would be taken for its answer to the next job (its end is found by the job)."""
        assert self.process is not None and self.process.stdout is not None
        with selectors.DefaultSelector() as selector:
            selector.register(self.process.stdout, selectors.EVENT_READ)
            return bool(selector.select(0)) and bool(os.read(self.process.stdout.fileno(),
                                                             1 << 16))

    def _gone(self, stream: str, doing: str) -> str:
        """What the engine did, which closed its standard `stream` (input or output):
        ended, with its exit status, or closed it alive; its standard error's end read
        (for at most a second, when another process holds it open)."""
        assert self.process is not None and self.process.stderr is not None
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.process.wait(1)
        deadline = time.monotonic() + 1
        with selectors.DefaultSelector() as selector:
            selector.register(self.process.stderr, selectors.EVENT_READ)
            while selector.select(max(deadline - time.monotonic(), 0)):
                chunk = os.read(self.process.stderr.fileno(), 1 << 16)
                if not chunk:
                    break
                self.stderr.extend(chunk)
                del self.stderr[:-STDERR_KEPT]
        status = self.process.poll()
        if status is None:
            return f"it closed its standard {stream} before {doing}"
        return f"it ended before {doing} (exit status {status})"

    def _failed(self, code: str, message: str) -> Observation:
        """The status of a job the engine did not answer; it is stopped, to start again
        at the next job."""
        said = self.stderr.decode("utf-8", "replace").strip().splitlines()
        self.close()
        return _no_run(code, message + (f"; its standard error ends: {said[-1]}"
                                        if said else ""))

    def close(self) -> None:
        """Stop the engine and every process it started."""
        if self.process is None:
            return
        process, self.process = self.process, None
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()
        for stream in (process.stdin, process.stdout, process.stderr):
            if stream is not None:
                with contextlib.suppress(OSError):
                    stream.close()


_BATCHES: dict[str, _Batch] = {}  # this process's batch engines, by command


@atexit.register
def _close_batches() -> None:
    for batch in _BATCHES.values():
        if batch.owner == os.getpid():
            batch.close()


@dataclass(frozen=True)
class _Ran:
    """How a shell command ended ("done", "timeout", "too-much-output"), and what it
    printed: its standard output whole, the end of its standard error."""

    ending: str
    stdout: bytes
    stderr: bytes


def _run_shell(command: str) -> _Ran:
    """Run `command` through the shell for at most EXEC_TIMEOUT seconds, reading at most
    EXEC_OUTPUT_LIMIT bytes of its output, which is what it printed by the shell's end (on
    Linux; elsewhere, by the end of its pipes, which a process it left running holds
    open); then every process it started is killed (the command runs in a process group
    of its own)."""
    process = subprocess.Popen(command, shell=True, stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               start_new_session=True)
    assert process.stdout is not None and process.stderr is not None
    stdout, stderr = bytearray(), bytearray()
    ending = "done"
    deadline = time.monotonic() + EXEC_TIMEOUT
    shell = _end_seen(process.pid)
    shell_ended = False  # then what it wrote is in the pipes, which a process it left
    # running (`sleep 300 &`) may hold open for ever: what is there is read, no more
    try:
        with selectors.DefaultSelector() as selector:
            selector.register(process.stdout, selectors.EVENT_READ, stdout)
            selector.register(process.stderr, selectors.EVENT_READ, stderr)
            if shell is not None:
                selector.register(shell, selectors.EVENT_READ)
            while ending == "done" and any(key.data is not None
                                           for key in selector.get_map().values()):
                left = deadline - time.monotonic()
                if left <= 0:
                    ending = "timeout"
                ready = selector.select(0 if shell_ended else max(left, 0))
                if shell_ended and not ready:
                    break
                for key, _ in ready:
                    if key.data is None:  # the shell's end
                        selector.unregister(key.fileobj)
                        shell_ended = True
                        continue
                    chunk = os.read(key.fd, 1 << 16)
                    if not chunk:
                        selector.unregister(key.fileobj)
                    key.data.extend(chunk)
                del stderr[:-STDERR_KEPT]
                if len(stdout) > EXEC_OUTPUT_LIMIT:
                    ending = "too-much-output"
        if ending == "done":
            try:
                process.wait(max(deadline - time.monotonic(), 0))
            except subprocess.TimeoutExpired:
                ending = "timeout"
    finally:
        # Before wait(), so that the group's id is still the command's. Gone: they all
        # ended already; not permitted: what is left runs as another user (setuid).
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()
        process.stdout.close()
        process.stderr.close()
        if shell is not None:
            os.close(shell)
    return _Ran(ending, bytes(stdout), bytes(stderr))


def _end_seen(pid: int) -> int | None:
    """A file descriptor readable once the process `pid` (a child not yet waited for)
    has ended: a Linux pidfd; None where there is none."""
    try:
        return os.pidfd_open(pid)
    except (AttributeError, OSError):  # not Linux, or a kernel before 5.3
        return None


def _no_run(code: str, message: str) -> Observation:
    return Observation({"status": {"code": code, "line": None, "message": message},
                        "variables": {}, "trace": []})


def printed_run(stdout: bytes, stderr: bytes) -> dict[str, Any]:
    """The run an exec: engine printed, or a status saying it printed none, and why."""
    try:
        document: object = json.loads(stdout, parse_int=decimal_value)
    except (ValueError, RecursionError):  # not JSON, nor UTF-8, or nested too deeply
        problem: str | None = "it printed no JSON"
    else:
        problem = _shape_problem(document)
    if problem is None and isinstance(document, dict):
        return document
    said = stderr.decode("utf-8", "replace").strip().splitlines()
    return _no_run("no-run", f"{problem}" + (f"; its standard error ends: {said[-1]}"
                                             if said else "")).document


def _shape_problem(document: object) -> str | None:
    """What keeps `document` from being a run as `rl1c run --format json` prints it
    (section 5 of spec/optimization.md); None when it is one."""
    if not isinstance(document, dict):
        return "it printed JSON but no object"
    missing = [key for key in ("status", "variables", "trace") if key not in document]
    if missing:
        return f"its object has no {' nor '.join(missing)}"
    status, variables, trace = document["status"], document["variables"], document["trace"]
    if status != "ok" and not (isinstance(status, dict) and isinstance(status.get("code"), str)
                               and (status.get("line") is None or _whole(status["line"]))):
        return 'its status is neither "ok" nor an object with a code and a line'
    if not isinstance(variables, dict) or not all(map(_whole, variables.values())):
        return "its variables are not an object of whole numbers"
    if not isinstance(trace, list):
        return "its trace is not a list"
    for index, entry in enumerate(trace, 1):
        if not (isinstance(entry, dict) and _whole(entry.get("time"))
                and isinstance(entry.get("call"), str) and _numbers(entry.get("args"))
                and (entry.get("result") is None or _numbers(entry["result"]))):
            return (f"its trace entry {index} is not an object with a time, a call, its "
                    "arguments and what it read")
    return None


def _whole(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _numbers(value: object) -> bool:
    return isinstance(value, list) and all(map(_whole, value))


def compiled(source: str, level: int) -> bytes:
    """The .ilc bytes of a generated program (which the checker accepts), the IR
    validated after every pass."""
    output = compile_text(source, SOURCE_NAME, level=level, check=True).output
    assert output is not None, "a generated program has errors"
    return output


DEFAULT_ENGINES = ("ast", *(f"vm-O{level}" for level in OPTIMIZATION_LEVELS))
ENGINE_NAMES = (*DEFAULT_ENGINES, *(f"c-O{level}" for level in OPTIMIZATION_LEVELS))


EXEC_ENGINE = re.compile(r"exec(-batch)?(?:-O([0-9]+))?:(.*\S.*)", re.DOTALL)
"""`exec:COMMAND` (given the -O0 file) or `exec-ON:COMMAND` (the file at -ON), and the
same with `exec-batch`."""


def _exec_name(kind: str, level: int, command: str) -> str:
    """The name of an `exec` or `exec-batch` engine, as EXEC_ENGINE reads it back."""
    return f"{kind}{f'-O{level}' if level else ''}:{command}"


def engine_named(name: str) -> Engine | None:
    """The engine a name on the command line means; None when it means none."""
    if name == "ast":
        return AstEngine()
    if name.startswith("vm-O") and name[4:] in {str(level) for level in OPTIMIZATION_LEVELS}:
        return VmEngine(int(name[4:]))
    if name.startswith("c-O") and name[3:] in {str(level) for level in OPTIMIZATION_LEVELS}:
        return CEngine(int(name[3:]))
    if (written := EXEC_ENGINE.fullmatch(name)) is not None:
        batch, level, command = written.group(1), int(written.group(2) or 0), written.group(3)
        if level not in OPTIMIZATION_LEVELS:
            return None
        return BatchEngine(command, level) if batch else ExecEngine(command, level)
    return None


# Comparing runs --------------------------------------------------------------------------

Rule = Literal["same-code", "invariant", "shared-prefix"]
SAME_CODE: Rule = "same-code"  # both ran the same code: everything compares, the watchdog too
INVARIANT: Rule = "invariant"  # the reference is the -O0 VM's run: section 3 says what compares
SHARED_PREFIX: Rule = "shared-prefix"  # two runs past an -O0 run that met the watchdog


def differences(reference: Observation, other: Observation, rule: Rule = INVARIANT
                ) -> list[str]:
    """How `other` differs from `reference`, one line each; empty when they agree.

    What compares when a run meets the watchdog depends on how the two count steps
    (spec/optimization.md, sections 3 and 5), the `rule`:
    - SAME_CODE: they ran the same code (the same file), so they count the same
      instructions: everything compares, a watchdog's fault like any other ending.
    - INVARIANT: `reference` is the -O0 VM's run, `other` the same program run at a
      level or by an engine that never counts more to a call (the interpreter counts
      statements). An -O0 run that ended is matched in everything, so `other` meeting
      the watchdog is a difference; one that met the watchdog must have its trace up to
      the fault as a prefix of `other`'s, whose ending and variables are its own.
    - SHARED_PREFIX: neither is the -O0 run, which met the watchdog: only their traces up
      to the shorter compare."""
    found: list[str] = []
    ours, theirs = reference.commands(), other.commands()
    match rule:  # how much of the traces compares, when not all of the runs
        case "invariant" if reference.ran_away:
            compared: int | None = len(ours)
        case "shared-prefix" if reference.ran_away or other.ran_away:
            compared = min(len(ours), len(theirs))
        case _:
            compared = None
    if compared is not None:
        ours, theirs = ours[:compared], theirs[:compared]
    for index, (mine, yours) in enumerate(zip(ours, theirs, strict=False)):
        if mine != yours:
            found.append(f"trace entry {index + 1}: {_entry(mine)} / {_entry(yours)}")
            break
    else:
        if len(ours) != len(theirs):
            longer = ours if len(ours) > len(theirs) else theirs
            found.append(f"trace: {len(ours)} / {len(theirs)} entries, the first extra "
                         f"one {_entry(longer[min(len(ours), len(theirs))])}")
    if compared is not None:
        return found
    if reference.ending() != other.ending():
        found.append(f"ending: {_ending(reference)} / {_ending(other)}")
    mine_vars = reference.document.get("variables", {})
    your_vars = other.document.get("variables", {})
    changed = [name for name in VARIABLES if mine_vars.get(name) != your_vars.get(name)]
    if changed:
        found.append("variables: " + ", ".join(
            f"{name} {mine_vars.get(name)} / {your_vars.get(name)}" for name in changed[:8])
            + (f" and {len(changed) - 8} more" if len(changed) > 8 else ""))
    return found


def budget_violations(unoptimized: Observation, optimized: Observation,
                      budget: int) -> list[str]:
    """Where an optimized VM run breaks the budget invariant (spec/optimization.md,
    section 3) against the -O0 run of the same program."""
    found: list[str] = []
    before, after = unoptimized.call_counts or (), optimized.call_counts or ()
    for index, (then, now) in enumerate(zip(before, after, strict=False)):
        if now > then:
            found.append(f"call {index + 1} comes after {now} instructions, "
                         f"-O0 reached it after {then}")
            break
    ended = not unoptimized.ran_away and (unoptimized.executed or 0) <= budget
    if ended and optimized.ran_away:
        found.append("met the watchdog where -O0 ended within the budget")
    if ended and not optimized.ran_away and (optimized.executed or 0) > (
            unoptimized.executed or 0):
        found.append(f"ran {optimized.executed} instructions, -O0 {unoptimized.executed}")
    return found


@dataclass(frozen=True)
class Verdict:
    """Every engine's run of one case, and what disagrees (empty when all agree)."""

    observations: dict[str, Observation]
    problems: list[str]
    ended: str | None = None  # judge_apart: how an engine ended its process, if one did


def _observed(engine: Engine, case: Run, budget: int) -> Observation:
    """The engine's run, or the status `crash` when its compiler or VM raised: a crash
    is a finding that `rl1c fuzz` shrinks and writes down like a disagreement."""
    try:
        return engine.run(case, budget)
    except (BuildError, EngineUnavailable):  # this machine's doing, not the program's
        raise
    except Exception as error:  # whatever it raised is what was found
        return Observation({"status": {"code": CRASH_CODE, "line": None,
                                       "message": f"{type(error).__name__}: {error}"},
                            "variables": {}, "trace": []})


WITNESS = VmEngine(0)  # whose run decides what compares when the watchdog is met


def judge(case: Run, engines: Sequence[Engine], budget: int) -> Verdict:
    """Run `case` on every engine; compare each with the first, and with the -O0 VM's
    run as the budget invariant says (spec/optimization.md, sections 3 and 5)."""
    if parse_script(case.script).instruction_losses:
        return _judge_by_level(case, engines, budget)
    observations = {engine.name: _observed(engine, case, budget) for engine in engines}
    problems = _crashes(observations)
    reference, *others = engines
    witness = observations.get(WITNESS.name)
    if witness is None and any(observation.ran_away for observation in observations.values()):
        witness = _observed(WITNESS, case, budget)  # run only when it decides something
    if witness is not None and witness.ran_away:
        # Each engine has its trace up to -O0's fault, or all of it on the same code;
        # between two others, only what both ran compares.
        problems += [f"{engine.name}: {line}" for engine in engines
                     if engine.name != WITNESS.name
                     for line in differences(witness, observations[engine.name],
                                             SAME_CODE if engine.level == 0 else INVARIANT)]
        pairs_rule = SHARED_PREFIX
    else:  # -O0 ended within the budget, so every engine ends as it does
        pairs_rule = SAME_CODE
        if witness is not None and not witness.crashed:
            executed = witness.executed
            problems += [f"{name}: met the watchdog, where vm-O0 ended after {executed} "
                         f"instruction{'s' if executed != 1 else ''} of the budget of {budget}"
                         for name, observation in observations.items() if observation.ran_away]
    if reference.name != WITNESS.name or pairs_rule == SAME_CODE:
        problems += [f"{engine.name}: {line}" for engine in others
                     for line in differences(
                         observations[reference.name], observations[engine.name],
                         SAME_CODE if engine.level == reference.level is not None
                         else pairs_rule)]
    unoptimized = observations.get(WITNESS.name)
    if unoptimized is not None:
        problems += [f"{name}: {line}" for name in observations
                     if name.startswith("vm-O") and name != WITNESS.name
                     for line in budget_violations(unoptimized, observations[name], budget)]
    return Verdict(observations, list(dict.fromkeys(problems)))


def _judge_by_level(case: Run, engines: Sequence[Engine], budget: int) -> Verdict:
    """A script that loses the line after instruction counts names points in one
    compiled program: only engines given the same file compare, each with the first of
    its level, in everything; the interpreter, which counts statements, does not run."""
    observations: dict[str, Observation] = {}
    problems: list[str] = []
    first_of_level: dict[int, str] = {}
    for engine in engines:
        if engine.level is None:
            continue
        observations[engine.name] = observed = _observed(engine, case, budget)
        reference = first_of_level.setdefault(engine.level, engine.name)
        if reference != engine.name:
            problems += [f"{engine.name}: {line}" for line in
                         differences(observations[reference], observed, SAME_CODE)]
    return Verdict(observations, _crashes(observations) + problems)


def judge_apart(case: Run, engines: Sequence[Engine], budget: int) -> Verdict:
    """`judge` in a process of its own (forked from this one when it runs one thread,
    else spawned: `forks_safely`), so that an engine that
    ends the process it runs in (the C VM's segmentation fault, a sanitizer's abort, the
    memory exhausted) ends that one, not this: then the Verdict has the runs of the
    engines before it, and its one problem `NAME: ended its process (HOW)`, HOW the
    signal or the exit status. The errors of this machine (BuildError,
    EngineUnavailable) and of judge itself are raised here as the child raised them.

    The engines that run programs in processes of their own (`runs_elsewhere`) cannot
    end this one: they run here, before the fork, and the child is given their runs, so
    that a batch engine's process, started here once, answers every case judged apart
    rather than being started and ended in each child."""
    ran_here = {engine.name: _observed(engine, case, budget) for engine in engines
                if runs_elsewhere(engine)}
    judged = [_RanBefore(engine, ran_here[engine.name]) if engine.name in ran_here
              else engine for engine in engines]
    reading, writing = os.pipe()
    waited: Callable[[], int]  # waits for the child, and gives its exit code
    if forks_safely():
        child = os.fork()
        if child == 0:
            os.close(reading)
            _judge_in_child(writing, case, judged, budget)
        os.close(writing)

        def waited() -> int:
            return os.waitstatus_to_exitcode(os.waitpid(child, 0)[1])
    else:
        try:
            waited = spawn(_judge_in_child, writing, case, judged, budget,
                          keep=(writing,)).wait
        except BaseException:  # such as an engine that cannot be pickled
            os.close(reading)
            raise
        finally:
            os.close(writing)
    observations: dict[str, Observation] = {}
    running = ""  # the engine that started and has not finished, if any
    told: Verdict | BaseException | None = None
    try:
        with open(reading, "rb") as stream:
            while told is None:
                try:
                    message = pickle.load(stream)
                except (EOFError, pickle.UnpicklingError):  # ended, perhaps mid-message
                    break
                match message:
                    case ("started", str(name)):
                        running = name
                    case ("ran", str(name), Observation() as observation):
                        observations[name], running = observation, ""
                    case ("verdict", Verdict() as told):
                        pass
                    case ("raised", bytes(data), str(text)):
                        told = unpickled_error(data, text)
    finally:
        code = waited()
    if isinstance(told, BaseException):
        raise told
    if told is not None:
        return told
    how = exit_how(code)
    if not running:  # after the runs, as they were compared
        return Verdict(observations, [f"{ENDED} ({how}) as the runs were compared"], how)
    ended = Observation({"status": {"code": ENDED_CODE, "line": None, "message": how},
                         "variables": {}, "trace": []})
    return Verdict({**observations, running: ended}, [f"{running}: {ENDED} ({how})"], how)


def forks_safely() -> bool:
    """Whether judge_apart may fork this process: it runs one thread. A fork copies the
    thread that makes it alone, and the locks the others held then (the allocator's,
    logging's, an event loop's) stay held in the child for ever, so that it may
    deadlock; Python 3.12 warns of it. A Dask worker runs its tasks in threads beside
    its event loop's. A spawned process costs a case some 0.2 to 0.5 s more than a fork
    (bench/own_process.py: cases judged apart a second, forked 16 to 42, spawned 2 to
    4), so the fork is kept where it is safe: rl1c's own process, a local pool's
    worker, the process a cluster's task has of its own (executors.in_own_process)."""
    return threading.active_count() == 1


def _judge_in_child(writing: int, case: Run, engines: Sequence[Engine], budget: int
                    ) -> None:
    """`judge_apart`'s child, forked or spawned: tells each engine as it starts and ends,
    then the verdict (or what judge raised), on the pipe `writing`, and ends without
    returning."""
    try:
        ignore_interrupts()
        with open(writing, "wb") as stream:
            def tell(*message: object) -> None:
                stream.write(pickle.dumps(message))  # whole, or not at all
                stream.flush()

            try:
                tell("verdict", judge(case, [_Told(engine, tell) for engine in engines],
                                      budget))
            except BaseException as error:  # the parent raises it
                tell("raised", *pickled_error(error))
    finally:
        _close_batches()  # a process forked from this one ends without atexit's calls
        os._exit(0)


@dataclass(frozen=True)
class _StandingFor:
    """An engine in the place of `engine`, under its name and level."""

    engine: Engine

    @property
    def name(self) -> str:
        return self.engine.name

    @property
    def level(self) -> int | None:
        return self.engine.level


@dataclass(frozen=True)
class _Told(_StandingFor):
    """An engine whose runs `tell` (started, then ran with the observation)."""

    tell: Callable[..., None]

    def run(self, case: Run, budget: int) -> Observation:
        self.tell("started", self.name)
        observation = self.engine.run(case, budget)
        self.tell("ran", self.name, observation)
        return observation


@dataclass(frozen=True)
class _RanBefore(_StandingFor):
    """An engine whose run of the case judged was made before the fork."""

    observation: Observation

    def run(self, case: Run, budget: int) -> Observation:
        return self.observation


def runs_elsewhere(engine: Engine) -> bool:
    """Whether `engine` runs programs in processes of its own (the exec and batch
    engines), so that nothing a run does can end the process that asks for it."""
    return isinstance(engine, ExecEngine | BatchEngine)


def signature(verdict: Verdict) -> str:
    """What a disagreement is, the same for two programs that show one bug: for each
    engine that disagrees, the kind of its first difference, with what varies from
    program to program left out (the numbers of a trace entry, its time, the lines and
    values): the calls of the first differing trace entry, the two endings' codes, an
    exception's type and message with its numbers as N. `rl1c fuzz --keep-going`
    groups its findings by it."""
    names = sorted(verdict.observations, key=len, reverse=True)  # `exec:a b` before `exec:a`
    first: dict[str, str] = {}
    for problem in verdict.problems:
        name = next((name for name in names if problem.startswith(f"{name}: ")), "")
        first.setdefault(name, _kind(problem[len(name) + 2 if name else 0:]))
    return " | ".join(f"{name}: {kind}" if name else kind for name, kind in first.items())


_NUMBER = re.compile(r"(?<!\w)-?[0-9]+")  # not the 0 of vm-O0
_CALL = re.compile(r"[^0-9-]*")  # a trace entry as `_entry` writes it, up to its arguments


def _call(entry: str) -> str:
    return _CALL.match(entry).group().strip()  # type: ignore[union-attr]


def _kind(difference: str) -> str:
    """One line of `differences` (or of the budget invariant, or a crash) without what
    varies between two programs that show one bug."""
    match difference.split(": ", 1):
        case [ended] if ended.startswith(ENDED):  # its signal or exit status kept
            return ended
        case ["variables", _]:
            return "variables"
        case ["ending", endings]:
            return "ending: " + re.sub(r" at line [0-9]+", "", endings)
        case [entry, sides] if entry.startswith("trace entry "):
            return "trace entry: " + " / ".join(map(_call, sides.split(" / ", 1)))
        case ["trace", extra]:
            return "trace: extra " + _call(extra.rsplit(" one ", 1)[-1])
        case _:
            return _NUMBER.sub("N", difference)


def _crashes(observations: dict[str, Observation]) -> list[str]:
    return [f"{name}: crashed: {observation.document['status']['message']}"
            for name, observation in observations.items() if observation.crashed]


def _entry(entry: Any) -> str:
    if not isinstance(entry, dict):
        return repr(entry)
    args = ",".join(map(str, entry.get("args", [])))
    result = entry.get("result")
    read = " -> " + " ".join(map(str, result)) if result is not None else ""
    return f"{entry.get('call')} {args}{read} at {entry.get('time')} ms".replace("  ", " ")


def _ending(observation: Observation) -> str:
    match observation.ending():
        case {"code": "ok"}:
            return "ended normally"
        case {"code": code, "line": line}:
            return f"fault {code}" + (f" at line {line}" if line else "")
        case other:
            return repr(other)

