"""`rl1-dap`: a Debug Adapter Protocol server over standard input and output, on the
debugging core (compiler/debugger.py).

A client launches a `.rob` file (compiled in memory at the level asked, the default
`rl1c run`'s) or an `.ilc` file, on a sensor script (`sensors`) or in a world (`world`,
the simulator, with `seed`); sets line breakpoints (with conditions written as the
language writes a value: `A<0`), function breakpoints on calls (`IMG`, `CAM P`), and
the exception breakpoints `lost-line`; and steps (`next` a line, `stepIn` a line or,
with granularity `instruction`, an instruction), continues, pauses and restarts. A fault
always stops the run as an exception on its line, and ends it. One thread, the program;
one frame, its line; three scopes: the user variables (A-Z, a-r, @), the reserved
variables (s-z) and the device; `evaluate` computes a value (`U-L`) for a watch or a
hover. Each call the device receives is an `output` event.

Messages are framed as LSP's are, read by lsp/framing.py's bounded reader. The program
runs in a worker thread while the reader answers, so that `pause` reaches it.
"""

from __future__ import annotations

import json
import os
import reprlib
import stat
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO

import click

from rl1.compiler.campaign import MAX_SEED
from rl1.compiler.cli.command import ToolCommand, command_line_status
from rl1.compiler.debugger import (
    MAX_EXPRESSION,
    DebugError,
    Session,
    Stop,
    compile_program,
    parse_call,
    parse_value,
)
from rl1.compiler.files import SourceError, read_bounded
from rl1.compiler.frontend.source import read_source
from rl1.compiler.runner import load_script
from rl1.vm.config import excerpt
from rl1.vm.defaults import DEFAULT_BUDGET
from rl1.vm.device import Device
from rl1.vm.language import VARIABLES
from rl1.vm.scripted import ScriptedDevice, TraceEntry
from rl1.vm.sensor_script import ScriptError
from rl1.vm.sim.device import SimEntry
from rl1.vm.verifier import VerifyError

from .framing import CHUNK, Framer, frame, standard_streams
from .json_reading import read_json
from .studio.files import MAX_PATH

THREAD = 1
FRAME = 1
USER, RESERVED, DEVICE = 1, 2, 3  # the scopes' variablesReference
RESERVED_NAMES = "stuvwxyz"
MAX_ILC_BYTES = 16 * 2**20
MAX_WORLD_BYTES = 16 * 2**20

CAPABILITIES: dict[str, Any] = {
    "supportsConfigurationDoneRequest": True,
    "supportsConditionalBreakpoints": True,
    "supportsFunctionBreakpoints": True,
    "supportsRestartRequest": True,
    "supportsSteppingGranularity": True,
    "supportsExceptionInfoRequest": True,
    "supportsEvaluateForHovers": True,
    "exceptionBreakpointFilters": [
        {"filter": "lost-line", "label": "Lost lines",
         "description": "Stop where the program jumps to a lost-line handler (:96-:99)",
         "default": False},
    ],
}

_STOP_REASONS = {"entry": "entry", "step": "step", "breakpoint": "breakpoint",
                 "call": "function breakpoint", "lost-line": "exception",
                 "pause": "pause", "fault": "exception"}


class Refused(Exception):
    """A request the adapter cannot carry out; the message says why and what to do."""


class Adapter:
    """One client's debugging session: the requests, answered through `send`."""

    def __init__(self, send: Callable[[dict[str, Any]], None]) -> None:
        self._send = send
        self._seq = 0
        self._lock = threading.Lock()  # one message written at a time
        self.session: Session | None = None
        self.program_path = ""
        self.stop_on_entry = False
        self.done = False  # after disconnect
        self._worker: threading.Thread | None = None
        self._running = False  # till the worker has told where it stopped
        # Held while the worker tells a stop, so that a request waits until it is told
        # whole: never refused as running after the client heard of the stop, and never
        # let in before, to start a run whose events would come amid this one's.
        self._telling = threading.Lock()
        self._told = 0  # the trace entries already sent as output
        self._last_stop: Stop | None = None
        self._started = False  # by configurationDone, or a command before it

    # Writing

    def _write(self, message: dict[str, Any]) -> None:
        with self._lock:
            self._seq += 1
            self._send({"seq": self._seq, **message})

    def event(self, name: str, body: dict[str, Any] | None = None) -> None:
        self._write({"type": "event", "event": name,
                     **({} if body is None else {"body": body})})

    def _respond(self, request: dict[str, Any], body: dict[str, Any] | None = None) -> None:
        self._write({"type": "response", "request_seq": request["seq"], "success": True,
                     "command": request["command"], **({} if body is None else {"body": body})})

    def _refuse(self, request: dict[str, Any], message: str) -> None:
        # An excerpt of the command: one rl1-dap does not know may be megabytes long.
        self._write({"type": "response", "request_seq": request.get("seq", 0),
                     "success": False, "command": excerpt(request.get("command", "")),
                     "message": message,
                     "body": {"error": {"id": 1, "format": message, "showUser": True}}})

    # Reading

    def receive(self, body: bytes) -> None:
        """Handle one message's body."""
        try:
            message = read_json(body)
        except (ValueError, RecursionError) as error:
            print(f"rl1-dap: a message that is no JSON was skipped: {error}", file=sys.stderr)
            return
        if not isinstance(message, dict) or message.get("type") != "request" \
                or not _whole(message.get("seq")):
            print("rl1-dap: a message that is no DAP request (type, seq and command) was "
                  "skipped", file=sys.stderr)
            return
        if not isinstance(message.get("command"), str):  # answered: its client waits
            self._refuse({"seq": message["seq"]}, "a request's `command` is a string, such "
                                                  "as \"launch\": send one")
            return
        handler = getattr(self, "_on_" + message["command"], None)
        if handler is None:
            self._refuse(message, f"rl1-dap does not support the request "
                                  f"'{excerpt(message['command'])}'")
            return
        arguments = message.get("arguments", {})
        try:
            if not isinstance(arguments, dict):
                raise Refused("the request's arguments are not an object")
            _refuse_unknown_ids(arguments)
            handler(message, arguments)
        except Refused as refused:
            self._refuse(message, str(refused))
        except Exception as error:  # a bug of ours: the session goes on, and says so
            print(f"rl1-dap: internal error in '{message['command']}': {error!r}; please "
                  "report it", file=sys.stderr)
            self._refuse(message, f"rl1-dap failed on this request ({error!r}): please "
                                  "report it")

    # Requests

    def _on_initialize(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        self._respond(request, CAPABILITIES)

    def _on_launch(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        if self.session is not None:
            self._idle()  # a program running would go on, unseen, beside the new one
        program = _path(arguments.get("program"), "program")
        if program is None:
            raise Refused("launch needs `program`: the .rob or .ilc file to debug")
        image = self._image(program, arguments)
        make_device = _device_maker(arguments)
        budget = arguments.get("budget", DEFAULT_BUDGET)
        if not _whole(budget) or budget < 1:
            raise Refused(f"`budget` is {reprlib.repr(budget)}: give a whole number of "
                          "instructions, 1 or more")
        try:
            self.session = Session(image, make_device, budget)
        except VerifyError as error:
            raise Refused(f"{program}: byte {error.offset}: {error.message}; compile the "
                          "program again") from None
        self.program_path = str(Path(program).resolve())
        self.stop_on_entry = arguments.get("stopOnEntry") is True
        self._told, self._last_stop, self._started = 0, None, False  # a run of its own
        self._respond(request)
        self.event("initialized")

    def _image(self, program: str, arguments: dict[str, Any]) -> bytes:
        level = arguments.get("level")
        if level is not None and not (_whole(level) and level in (0, 1, 2)):
            raise Refused(f"`level` is {reprlib.repr(level)}: give 0, 1 or 2, as rl1c -O0..-O2")
        try:
            if _regular(program).lower().endswith(".ilc"):
                return read_bounded(program, MAX_ILC_BYTES, "an .ilc file")
            text = read_source(program).text
        except SourceError as error:
            raise Refused(f"{error}" + (f"; {error.help}" if error.help else "")) from None
        compiled = compile_program(text, os.path.basename(program), level)
        if isinstance(compiled, list):
            errors = [d for d in compiled if d.is_error]
            shown = "; ".join(f"{program}:{d.span.line}: {d.message}" for d in errors[:3])
            raise Refused(f"the program has errors, so it cannot run: {shown} (rl1c check "
                          f"{program} shows them all)")
        return compiled

    def _session(self) -> Session:
        if self.session is None:
            raise Refused("no program is launched: send launch first")
        return self.session

    def _on_setBreakpoints(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        session = self._session()
        wanted = _listed(arguments, "breakpoints")
        if not all(isinstance(b, dict) and _whole(b.get("line")) and b["line"] >= 1
                   and len(_condition(b) or "") <= MAX_EXPRESSION for b in wanted):
            raise Refused("`breakpoints` is a list of objects, each with a `line` (1 or "
                          f"more) and maybe a `condition` of {MAX_EXPRESSION:,} characters "
                          "at most")
        if (elsewhere := self._elsewhere(arguments.get("source"))) is not None:
            self._respond(request, {"breakpoints": [
                {"verified": False, "line": b["line"], "message": elsewhere} for b in wanted]})
            return
        bindings = session.set_line_breakpoints((b["line"], _condition(b)) for b in wanted)
        self._respond(request, {"breakpoints": [
            {"verified": True, "line": binding.line} if binding.verified else
            {"verified": False, "line": binding.requested, "message": binding.message}
            for binding in bindings]})

    def _elsewhere(self, source: object) -> str | None:
        """Why breakpoints in `source` (a DAP Source) are not the program's, or None when
        they are (a source without a path, as the tests send, is the program): a client
        sends every file's breakpoints, and they must not replace the program's."""
        match source:
            case None | {"path": None}:
                return None
            case {"path": str(path)}:
                _path(path, "source.path")
                try:
                    if os.path.realpath(path) == self.program_path:
                        return None
                except ValueError:  # a NUL, half a surrogate pair: no file's path
                    pass
                return (f"{path} is not the program being debugged, {self.program_path}: "
                        "rl1-dap debugs one program")
            case dict() if "path" not in source:
                return None
        raise Refused(f"`source` is {reprlib.repr(source)}: give an object with the file's `path`")

    def _on_setFunctionBreakpoints(self, request: dict[str, Any], arguments: dict[str, Any]
                                   ) -> None:
        session = self._session()
        answers, names = [], []
        for wanted in _listed(arguments, "breakpoints"):
            name = wanted.get("name") if isinstance(wanted, dict) else None
            try:
                if not isinstance(name, str) or len(name) > MAX_EXPRESSION:
                    raise DebugError("a function breakpoint's `name` is a built-in's: give "
                                     "a mnemonic of Table 2 or 3, as `IMG`, or a form, as "
                                     "`CAM P`")
                parse_call(name)
            except DebugError as error:
                answers.append({"verified": False, "message": str(error)})
                continue
            names.append(name)
            answers.append({"verified": True})
        session.set_call_breakpoints(names)
        self._respond(request, {"breakpoints": answers})

    def _on_setExceptionBreakpoints(self, request: dict[str, Any], arguments: dict[str, Any]
                                    ) -> None:
        self._session().stop_on_lost_line = "lost-line" in _listed(arguments, "filters")
        self._respond(request)

    def _on_configurationDone(self, request: dict[str, Any], arguments: dict[str, Any]
                              ) -> None:
        session = self._session()
        if self._started:  # a second run would step the machine beside the first
            raise Refused("the run has started: configurationDone comes once, after launch")
        self._respond(request)
        self._start(session)

    def _start(self, session: Session) -> None:
        """The run from its start: stopped on entry, or continued to its first stop."""
        self._started = True
        if self.stop_on_entry:
            self._stopped(Stop("entry", session.line))
        else:
            self._go(session.continue_)

    def _on_continue(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        session = self._idle()
        self._respond(request, {"allThreadsContinued": True})
        self._go(session.continue_)

    def _on_next(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        session = self._idle()
        self._respond(request)
        self._go(session.step_instruction if arguments.get("granularity") == "instruction"
                 else session.step_line)

    _on_stepIn = _on_next  # no subroutines: stepping in is stepping on

    def _on_pause(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        self._session().pause()
        self._respond(request)

    def _on_restart(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        session = self._idle()
        session.restart()
        self._told = 0
        self._last_stop = None
        self._respond(request)
        self._start(session)

    def _on_threads(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        self._respond(request, {"threads": [{"id": THREAD, "name": "program"}]})

    def _on_stackTrace(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        session = self._session()
        stop = self._last_stop
        line = stop.line if stop is not None and stop.reason == "fault" else session.line
        frame_: dict[str, Any] = {"id": FRAME, "name": "program", "line": line or 0,
                                  "column": 1 if line else 0}
        if line:
            frame_["source"] = {"name": os.path.basename(self.program_path),
                                "path": self.program_path}
        self._respond(request, {"stackFrames": [frame_], "totalFrames": 1})

    def _on_scopes(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        self._respond(request, {"scopes": [
            {"name": "Variables", "variablesReference": USER, "expensive": False},
            {"name": "Reserved variables", "variablesReference": RESERVED, "expensive": False},
            {"name": "Device", "variablesReference": DEVICE, "expensive": False},
        ]})

    def _on_variables(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        session = self._session()
        reference = arguments.get("variablesReference")
        variables = session.variables
        if reference in (USER, RESERVED):
            names = [name for name in VARIABLES
                     if (name in RESERVED_NAMES) == (reference == RESERVED)]
            shown = [{"name": name, "value": str(variables[name]), "variablesReference": 0}
                     for name in names]
        elif reference == DEVICE:
            shown = [{"name": name, "value": _shown(value), "variablesReference": 0}
                     for name, value in session.device_state().items()]
        else:
            raise Refused(f"no variables have the reference {reprlib.repr(reference)}")
        self._respond(request, {"variables": shown})

    def _on_evaluate(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        """A watch or hover: a value of the language over the variables now (`U-L`)."""
        expression = arguments.get("expression")
        if not isinstance(expression, str):
            raise Refused("evaluate needs `expression`: a value, as `U-L`")
        if len(expression) > MAX_EXPRESSION:
            raise Refused(f"`expression` is longer than {MAX_EXPRESSION:,} characters: give a "
                          "value such as `U-L`")
        session = self._session()
        try:
            value = parse_value(expression).of(session.machine.variables)
        except DebugError as error:
            raise Refused(str(error)) from None
        self._respond(request, {"result": str(value), "variablesReference": 0})

    def _on_exceptionInfo(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        stop = self._last_stop
        if stop is None or stop.reason not in ("fault", "lost-line"):
            raise Refused("the program did not stop on an exception")
        code, _, text = stop.text.partition(": ") if stop.reason == "fault" else (
            "lost-line", "", stop.text)
        self._respond(request, {"exceptionId": code, "description": text or stop.text,
                                "breakMode": "always"})

    def _on_disconnect(self, request: dict[str, Any], arguments: dict[str, Any]) -> None:
        if self.session is not None:
            self.session.pause()
        self._respond(request)
        self.done = True

    _on_terminate = _on_disconnect

    # Running

    def _idle(self) -> Session:
        session = self._session()
        with self._telling:
            running = self._running
        if running:
            raise Refused("the program is running: pause it first")
        return session

    def _go(self, command: Callable[[], Stop]) -> None:
        self._started = True
        self._running = True
        self.event("continued", {"threadId": THREAD, "allThreadsContinued": True})
        self._worker = threading.Thread(target=self._run, args=(command,), daemon=True)
        self._worker.start()

    def _run(self, command: Callable[[], Stop]) -> None:
        """The worker: where `command` stops, told; a bug of ours ends the session, said
        (in its thread, it would print a traceback and leave the client waiting)."""
        try:
            stop = command()
            with self._telling:
                self._stopped(stop)
                self._running = False
        except Exception as error:
            self._running = False
            print(f"rl1-dap: internal error in the run: {error!r}; please report it",
                  file=sys.stderr)
            self.event("output", {"category": "stderr", "output": "rl1-dap failed running "
                                  f"the program ({error!r}): please report it\n"})
            self.event("terminated")

    def _stopped(self, stop: Stop) -> None:
        session = self._session()
        previous, self._last_stop = self._last_stop, stop
        self._tell_trace(session)
        # A fault is shown as an exception where it happened; the command after it ends.
        if stop.reason == "end" or (stop.reason == "fault" and previous == stop):
            self.event("exited", {"exitCode": 0 if stop.reason == "end" else
                                  _exit_status(session)})
            self.event("terminated")
            return
        self.event("stopped", {"reason": _STOP_REASONS[stop.reason], "threadId": THREAD,
                               "allThreadsStopped": True,
                               **({"description": stop.text, "text": stop.text}
                                  if stop.text else {})})

    def _tell_trace(self, session: Session) -> None:
        trace = session.trace
        for entry in trace[self._told:]:
            self.event("output", {"category": "console", "output": _described(entry) + "\n"})
        self._told = len(trace)


def _exit_status(session: Session) -> int:
    result = session.result
    return 0 if result is None or result.fault is None else result.fault.kind.exit_status


def _whole(value: object) -> bool:
    """Whether `value` is a JSON integer (true and false are no numbers here)."""
    return isinstance(value, int) and not isinstance(value, bool)


_IDS = {"threadId": ("thread", f"the program's is {THREAD}", THREAD),
        "frameId": ("frame", f"the program's line is frame {FRAME}", FRAME)}


def _refuse_unknown_ids(arguments: dict[str, Any]) -> None:
    """Refuse a thread or a frame the adapter never gave out, in any request."""
    for key, (what, ours, given) in _IDS.items():
        if key in arguments and not (_whole(arguments[key]) and arguments[key] == given):
            raise Refused(f"no {what} has the id {reprlib.repr(arguments[key])}: {ours}")


def _condition(breakpoint: dict[str, Any]) -> str | None:
    condition = breakpoint.get("condition")
    return condition if isinstance(condition, str) else None


def _listed(arguments: dict[str, Any], key: str) -> list[Any]:
    value = arguments.get(key, [])
    if not isinstance(value, list):
        raise Refused(f"`{key}` is {reprlib.repr(value)}: give a list")
    return value


def _path(value: object, key: str) -> str | None:
    """A file's path the client gave as `key`, or None when it gave none."""
    if value is not None and not isinstance(value, str):
        raise Refused(f"`{key}` is {reprlib.repr(value)}: give a file's path as a string")
    if value is not None and len(value) > MAX_PATH:  # not quoted whole in a refusal
        raise Refused(f"`{key}` is longer than {MAX_PATH:,} characters, longer than any "
                      "file's path: name a file")
    return value


def _device_maker(arguments: dict[str, Any]) -> Callable[[], Device]:
    # each name written out: the VS Code extension's test reads the names from here
    sensors = _path(arguments.get("sensors"), "sensors")
    world = _path(arguments.get("world"), "world")
    if sensors is not None and world is not None:
        raise Refused("give `sensors` (a sensor script) or `world` (the simulator's world), "
                      "not both")
    if world is not None:
        from rl1.vm.sim.device import SimDevice
        from rl1.vm.sim.world import WorldError, decode_world

        seed = arguments.get("seed", 0)
        if not (_whole(seed) and 0 <= seed <= MAX_SEED):
            raise Refused(f"`seed` is {reprlib.repr(seed)}: give a whole number from 0 to "
                          f"{MAX_SEED}, as rl1c sim --seed")
        try:
            the_world = decode_world(read_bounded(_regular(world), MAX_WORLD_BYTES,
                                                  "a world file"), world)
        except (SourceError, WorldError) as error:
            raise Refused(str(error)) from None
        return lambda: SimDevice(the_world, seed=seed)
    try:
        script = load_script(_regular(sensors)) if sensors is not None else None
    except (SourceError, ScriptError) as error:
        raise Refused(str(error)) from None
    return lambda: ScriptedDevice(script)


_KINDS = ((stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _regular(path: str) -> str:
    """`path`, refused when it names no file (a NUL, half a surrogate pair) or a file
    that is neither regular nor a folder (which reading refuses with why): a FIFO waits
    for a writer, and the adapter, which reads its client's requests in the thread
    that reads files, would stop answering; a device is no program, world or script."""
    try:
        mode = os.stat(path).st_mode
    except (ValueError, UnicodeEncodeError):
        raise Refused(f"`{path!r}` is no file's path: give the path of a file") from None
    except OSError:  # reading says what is wrong
        return path
    kind = next((kind for test, kind in _KINDS if test(mode)), None)
    if kind is not None:
        raise Refused(f"{path}: it is {kind}, not a regular file: name one")
    return path


def _shown(value: object) -> str:
    return value if isinstance(value, str) else json.dumps(value)


def _described(entry: TraceEntry | SimEntry) -> str:
    match entry:
        case TraceEntry():
            return f"{entry.time} ms, line {entry.line}: {entry.describe()}"
        case SimEntry():
            args = ",".join(map(str, entry.args))
            result = "" if entry.result is None else " -> " + " ".join(map(str, entry.result))
            return f"{entry.time:.3f} s, line {entry.line}: {entry.call} {args}{result}"


def serve(input_: BinaryIO, output: BinaryIO) -> None:
    """Answer the requests read from `input_` on `output` until disconnect or the input's
    end."""
    def send(message: dict[str, Any]) -> None:
        try:
            output.write(frame(json.dumps(message, separators=(",", ":")).encode("utf-8")))
            output.flush()
        except OSError:  # the client has gone: its input ends too
            adapter.done = True

    adapter = Adapter(send)
    framer = Framer()
    while not adapter.done:
        chunk = os.read(input_.fileno(), CHUNK)
        if not chunk:
            break
        for body in framer.feed(chunk):
            adapter.receive(body)
            if adapter.done:
                break
        for problem in framer.problems:
            print(f"rl1-dap: skipped {problem}; reading on from the next Content-Length "
                  "header", file=sys.stderr)
        framer.problems.clear()


NAME = "rl1-dap"


@click.command(NAME, cls=ToolCommand)
@click.version_option(package_name="rl1", prog_name=NAME)
def command() -> None:
    """The RL/I debug adapter: the Debug Adapter Protocol over standard input and output,
    for VS Code, nvim-dap and any DAP client. Launch a .rob (compiled in memory, `level`
    0 to 2) or an .ilc file with `sensors` (a sensor script) or `world` (a world file);
    breakpoints on lines (with conditions such as A<0), on calls (IMG) and on lost lines
    and faults; stepping by line or instruction; the variables and the device."""
    serve(*standard_streams())


def main(argv: list[str] | None = None) -> None:
    """The `rl1-dap` command line (default: the process's arguments); a malformed one is
    said as rl1c's are: `rl1-dap: error: ...`, status 2."""
    sys.exit(command_line_status(
        lambda: command.main(argv, prog_name=NAME, standalone_mode=False), NAME))


if __name__ == "__main__":
    main()
