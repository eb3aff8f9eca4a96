"""The studio's protocol on one `/studio` WebSocket connection (spec/studio.md): JSON-RPC
2.0 requests from the page answered, and the run's notifications sent to it.

A connection holds the page's breakpoints and at most one run (run.py). Requests are
handled one at a time, in order; what reads or compiles files runs in a thread, so that
the other connections (the language server's among them) are not held up.
"""

from __future__ import annotations

import asyncio
import json
import logging
import reprlib
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import PurePosixPath
from typing import Any, ClassVar

from rl1.compiler.campaign import MAX_SEED
from rl1.compiler.debugger import (
    MAX_EXPRESSION,
    DebugError,
    compile_program,
    parse_call,
    parse_value,
)
from rl1.compiler.files import SourceError
from rl1.compiler.frontend.source import decode
from rl1.vm import ilc
from rl1.vm.config import excerpt
from rl1.vm.defaults import DEFAULT_BUDGET, DEFAULT_LEVEL
from rl1.vm.sensor_script import Script, ScriptError, decode_script
from rl1.vm.sim.world import World, WorldError, decode_world

from ..json_reading import read_json
from . import shapes
from .files import MAX_FILE_BYTES, Changed, Folder, Refused, Unusable, version_of
from .run import DEFAULT_SPEED, FRAMES_PER_SECOND, MAX_SPEED, MIN_SPEED, Launch, Run

log = logging.getLogger(__name__)

PARSE_ERROR = -32700
INVALID_REQUEST = -32600
NO_SUCH_METHOD = -32601
INVALID_PARAMS = -32602
FILE_REFUSED = -32001
FILE_UNUSABLE = -32002
PROGRAM_ERRORS = -32003
INVALID_CONFIG = -32004
NO_RUN = -32005
RUNNING = -32006
CHANGED = -32007

LEVELS = (0, 1, 2)
MAX_BREAKPOINTS = 10_000
"""Line breakpoints, and call breakpoints, a page may set: binding them costs, on the
event loop, a search of the program's lines and a condition parsed (once) each."""
FRAME_BACKLOG = 2**20
"""Bytes the page has not read yet past which frames are dropped (the next one shows
where the vehicle is): a page that falls behind is not sent more to fall behind on."""


class RpcError(Exception):
    """A request that fails: its JSON-RPC error."""

    def __init__(self, code: int, message: str, data: dict[str, Any] | None = None) -> None:
        super().__init__(message)
        self.code = code
        self.data = data

    def to_json(self) -> dict[str, Any]:
        error: dict[str, Any] = {"code": self.code, "message": str(self)}
        if self.data is not None:
            error["data"] = self.data
        return error


@dataclass(frozen=True, slots=True)
class Studio:
    """What every connection shares: the folder, and the command line's files (paths
    in the folder, or None)."""

    folder: Folder
    program: str | None
    world: str | None


@dataclass(frozen=True, slots=True)
class Source:
    """A file of a launch: a path in the folder, or a text the editor holds (`name`
    naming it in messages)."""

    name: str
    path: str | None = None
    text: str | None = None


Send = Callable[[str], None]
"""Sends one text frame; `backlog()` below says how much is not sent yet."""


class Connection:
    """One page's connection: `receive` each text frame; `send` writes one."""

    def __init__(self, studio: Studio, send: Send, backlog: Callable[[], int]) -> None:
        self._studio = studio
        self._send = send
        self._backlog = backlog
        self._loop = asyncio.get_running_loop()
        self._run: Run | None = None
        self._lines: list[tuple[int, str | None]] = []
        self._calls: list[str] = []
        self._lost_lines = False

    # Messages

    async def receive(self, frame: str | bytes) -> None:
        """Handle one message, answering it unless it is a notification."""
        try:
            message = read_json(frame)
        except (ValueError, RecursionError) as error:
            self._answer(None, error=RpcError(PARSE_ERROR, f"the message is no JSON ({error}): "
                                                           "send one JSON-RPC request a frame"))
            return
        msg_id = message.get("id") if isinstance(message, dict) else None
        if not _is_id(msg_id):
            msg_id = None
        if not (isinstance(message, dict) and message.get("jsonrpc") == "2.0"
                and isinstance(message.get("method"), str) and _is_id(message.get("id"))):
            self._answer(msg_id, error=RpcError(INVALID_REQUEST, (
                "the message is no JSON-RPC 2.0 request: send an object with "
                '"jsonrpc": "2.0", "method" (a string), "id" (a number or a string) and '
                '"params" (an object)')))
            return
        method, params = message["method"], message.get("params", {})
        handler = self.METHODS.get(method)
        try:
            if handler is None:
                raise RpcError(NO_SUCH_METHOD, f"`{excerpt(method)}` is no method of the studio: "
                               f"the methods are {', '.join(self.METHODS)} (spec/studio.md)")
            if not isinstance(params, dict):
                raise RpcError(INVALID_PARAMS, "`params` is not an object: send an object, "
                               "{} when there is nothing to give")
            result = await handler(self, params)
        except RpcError as error:
            self._answer(msg_id, error=error)
        except Exception as error:  # a bug of ours: the connection goes on, and says so
            log.exception("rl1c studio: internal error in %s", method)
            self._answer(msg_id, error=RpcError(-32603, f"rl1c studio failed on `{method}` "
                                                f"({error!r}): please report it"))
        else:
            self._answer(msg_id, result)

    def _answer(self, msg_id: object, result: dict[str, Any] | None = None,
                error: RpcError | None = None) -> None:
        answer: dict[str, Any] = {"jsonrpc": "2.0", "id": msg_id}
        if error is not None:
            answer["error"] = error.to_json()
        else:
            answer["result"] = result
        self._send(json.dumps(answer))

    def notify(self, method: str, params: dict[str, Any]) -> bool:
        """Send a notification; False when it is a frame dropped for the backlog."""
        if method == "run/frame" and self._backlog() > FRAME_BACKLOG:
            return False
        self._send(json.dumps({"jsonrpc": "2.0", "method": method, "params": params}))
        return True

    def close(self) -> None:
        """The page has gone: its run stops."""
        if self._run is not None:
            self._run.close()
            self._run = None

    # Files

    async def _initialize(self, params: dict[str, Any]) -> dict[str, Any]:
        folder = self._studio.folder.root
        return {"version": version("rl1"), "folder": str(folder), "rootUri": folder.as_uri(),
                "program": self._studio.program, "world": self._studio.world,
                "levels": list(LEVELS), "defaultLevel": DEFAULT_LEVEL,
                "maxFramesPerSecond": FRAMES_PER_SECOND}

    async def _list(self, params: dict[str, Any]) -> dict[str, Any]:
        entries, truncated = await asyncio.to_thread(self._studio.folder.listing)
        return {"files": [entry.to_json() for entry in entries], "truncated": truncated}

    async def _read(self, params: dict[str, Any]) -> dict[str, Any]:
        path = _string(params, "path")
        data = await _files(asyncio.to_thread(self._studio.folder.read, path))
        version = version_of(data)
        if path.endswith(".rob"):
            try:
                source = decode(data, path)
            except SourceError as error:
                raise RpcError(FILE_UNUSABLE, _said(error)) from None
            return {"path": path, "text": source.text, "encoding": source.encoding,
                    "version": version}
        return {"path": path, "text": _utf8(data, path), "encoding": "utf-8",
                "version": version}

    async def _save(self, params: dict[str, Any]) -> dict[str, Any]:
        path, text = _string(params, "path"), _string(params, "text")
        over = _string(params, "version") if params.get("version") is not None else None
        encoding = params.get("encoding", "utf-8")
        if encoding not in ("utf-8", "cp932"):
            raise RpcError(INVALID_PARAMS, f"`encoding` is {reprlib.repr(encoding)}: give "
                           "\"utf-8\" or \"cp932\"")
        try:
            data = text.encode(encoding)
        except UnicodeEncodeError as error:
            raise RpcError(FILE_UNUSABLE, f"`{path}` cannot be written in {encoding}: "
                           f"{text[error.start:error.end]!r} has no {encoding} form; save "
                           "it in utf-8") from None
        await _files(asyncio.to_thread(self._studio.folder.save, path, data, over))
        return {"path": path, "size": len(data), "version": version_of(data)}

    async def _check_world(self, params: dict[str, Any]) -> dict[str, Any]:
        text = _unicode(_string(params, "text"), "`text`")
        name = _unicode(_string(params, "path"), "`path`") if "path" in params else "world.toml"
        if len(text) > MAX_FILE_BYTES:
            raise RpcError(FILE_UNUSABLE, f"the world is larger than {MAX_FILE_BYTES // 2**20} "
                           "MiB, the most the studio reads")
        try:
            world = await asyncio.to_thread(decode_world, text.encode(), name)
        except WorldError as error:
            return {"errors": [shapes.config_problem(str(error))], "geometry": None}
        return {"errors": [], "geometry": shapes.geometry(world)}

    async def _palette(self, params: dict[str, Any]) -> dict[str, Any]:
        return {"builtins": shapes.palette()}

    # Launching

    async def _launch(self, params: dict[str, Any]) -> dict[str, Any]:
        program = _source(params, "program", "program.rob")
        if program is None:
            raise RpcError(INVALID_PARAMS, "`program` is missing: give {\"path\": ...} or "
                           "{\"text\": ..., \"name\": ...}")
        world = _source(params, "world", "world.toml")
        sensors = _source(params, "sensors", "sensors.json")
        if world is not None and sensors is not None:
            raise RpcError(INVALID_PARAMS, "give `world` (the simulator) or `sensors` (a "
                           "sensor script), not both")
        level = params.get("level")
        if level is not None and not (_whole(level) and level in LEVELS):
            raise RpcError(INVALID_PARAMS, f"`level` is {reprlib.repr(level)}: give 0, 1, 2 "
                           "or null")
        seed = params.get("seed", 0)
        if not _whole(seed) or not 0 <= seed <= MAX_SEED:
            raise RpcError(INVALID_PARAMS, f"`seed` is {reprlib.repr(seed)}: give a whole "
                           f"number from 0 to {MAX_SEED}")
        speed = _speed(params) if "speed" in params else DEFAULT_SPEED
        stop_on_entry = params.get("stopOnEntry", False)
        if not isinstance(stop_on_entry, bool):
            raise RpcError(INVALID_PARAMS, f"`stopOnEntry` is {reprlib.repr(stop_on_entry)}: "
                           "give true or false")
        launch = await asyncio.to_thread(self._prepare, program, world, sensors, level, seed,
                                         stop_on_entry)
        self.close()
        run = self._run = Run(launch, self.notify, self._loop, speed)
        lines, calls = self._bind(run)
        run.command("start")
        return {"breakpoints": lines, "calls": calls,
                "lines": sorted({line for line in run.session.lines if line is not None})}

    def _prepare(self, program: Source, world: Source | None, sensors: Source | None,
                 level: int | None, seed: int, stop_on_entry: bool) -> Launch:
        """The launch's files read and checked, and the program compiled (in a thread)."""
        text = self._program_text(program)
        compiled = compile_program(text, _recorded(program.name), level)
        if isinstance(compiled, list):
            errors = [d for d in compiled if d.is_error]
            shown = "; ".join(f"{program.name}:{d.span.line}: {d.message}" for d in errors[:3])
            raise RpcError(PROGRAM_ERRORS, f"the program has errors, so it cannot run: {shown}",
                           {"diagnostics": shapes.diagnostics(program.name, text, compiled)})
        the_world: World | None = None
        script: Script | None = None
        try:
            if world is not None:
                the_world = decode_world(self._bytes(world), world.name)
            if sensors is not None:
                script = decode_script(self._bytes(sensors), sensors.name)
        except (WorldError, ScriptError) as error:
            raise RpcError(INVALID_CONFIG, str(error),
                           {"errors": [shapes.config_problem(str(error))]}) from None
        return Launch(compiled, the_world, script, seed, DEFAULT_BUDGET, stop_on_entry)

    def _program_text(self, program: Source) -> str:
        if program.text is not None:
            return program.text
        try:
            return decode(self._bytes(program), program.name).text
        except SourceError as error:
            raise RpcError(FILE_UNUSABLE, _said(error)) from None

    def _bytes(self, source: Source) -> bytes:
        if source.text is not None:
            return source.text.encode()
        assert source.path is not None
        try:
            return self._studio.folder.read(source.path)
        except Refused as refused:
            raise RpcError(FILE_REFUSED, str(refused)) from None
        except Unusable as unusable:
            raise RpcError(FILE_UNUSABLE, str(unusable)) from None

    # Breakpoints

    async def _set_breakpoints(self, params: dict[str, Any]) -> dict[str, Any]:
        if "lines" in params:
            wanted = params["lines"]
            if not isinstance(wanted, list) or len(wanted) > MAX_BREAKPOINTS or not all(
                    isinstance(item, dict) and _whole(item.get("line")) and item["line"] >= 1
                    and isinstance(item.get("condition"), str | None)
                    and len(item.get("condition") or "") <= MAX_EXPRESSION for item in wanted):
                raise RpcError(INVALID_PARAMS, "`lines` is a list of objects, each with a "
                               "`line` (a whole number, 1 or more) and maybe a `condition` (a "
                               f"string of {MAX_EXPRESSION:,} characters at most), "
                               f"{MAX_BREAKPOINTS:,} at most")
            self._lines = [(item["line"], item.get("condition") or None) for item in wanted]
        if "calls" in params:
            calls = params["calls"]
            if not isinstance(calls, list) or len(calls) > MAX_BREAKPOINTS or not all(
                    isinstance(call, str) and len(call) <= MAX_EXPRESSION for call in calls):
                raise RpcError(INVALID_PARAMS, "`calls` is a list of strings, such as "
                               f"[\"IMG\", \"CAM P\"], {MAX_BREAKPOINTS:,} at most")
            self._calls = calls
        if "lostLines" in params:
            if not isinstance(params["lostLines"], bool):
                raise RpcError(INVALID_PARAMS, "`lostLines` is true or false")
            self._lost_lines = params["lostLines"]
        if self._run is None:
            return {"breakpoints": None, "calls": None}
        lines, calls = self._bind(self._run)
        return {"breakpoints": lines, "calls": calls}

    def _bind(self, run: Run) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
        """The page's breakpoints set on the run's session, as bound."""
        session = run.session
        bindings = session.set_line_breakpoints(self._lines)
        lines = []
        for binding, (_, condition) in zip(bindings, self._lines, strict=True):
            shown: dict[str, Any] = {"line": binding.requested, "boundTo": binding.line,
                                     "condition": condition, "verified": binding.verified}
            if not binding.verified:
                shown["message"] = binding.message
            lines.append(shown)
        calls, valid = [], []
        for name in self._calls:
            try:
                parse_call(name)
            except DebugError as error:
                calls.append({"name": name, "verified": False, "message": str(error)})
                continue
            valid.append(name)
            calls.append({"name": name, "verified": True})
        session.set_call_breakpoints(valid)
        session.stop_on_lost_line = self._lost_lines
        return lines, calls

    # Commands

    def _idle_run(self) -> Run:
        run = self._running_run()
        if run.busy:
            raise RpcError(RUNNING, "the program is running: pause it first")
        if run.over:
            raise RpcError(NO_RUN, "the run is over: restart it, or launch again")
        return run

    def _running_run(self) -> Run:
        if self._run is None:
            raise RpcError(NO_RUN, "no program is launched: send run/launch first")
        return self._run

    async def _continue(self, params: dict[str, Any]) -> dict[str, Any]:
        run = self._idle_run()
        if "speed" in params:
            run.set_speed(_speed(params))
        run.command("continue")
        return {}

    async def _step_line(self, params: dict[str, Any]) -> dict[str, Any]:
        self._idle_run().command("stepLine")
        return {}

    async def _step_instruction(self, params: dict[str, Any]) -> dict[str, Any]:
        self._idle_run().command("stepInstruction")
        return {}

    async def _pause(self, params: dict[str, Any]) -> dict[str, Any]:
        run = self._running_run()
        if run.busy:
            run.pause()
        return {}

    async def _restart(self, params: dict[str, Any]) -> dict[str, Any]:
        self._running_run().command("restart")
        return {}

    async def _stop(self, params: dict[str, Any]) -> dict[str, Any]:
        self._running_run()
        self.close()
        self.notify("run/ended", {"status": None, "variables": None, "instructions": None,
                                  "deviceTime": None, "goal": None, "frame": None,
                                  "trace": [], "events": [], "image": None})
        return {}

    async def _set_speed(self, params: dict[str, Any]) -> dict[str, Any]:
        if "speed" not in params:
            raise RpcError(INVALID_PARAMS, "`speed` is missing: give a number of times real "
                           f"time ({MIN_SPEED:g} to {MAX_SPEED:g}), or null for the fastest")
        speed = _speed(params)
        if self._run is not None:
            self._run.set_speed(speed)
        return {}

    async def _evaluate(self, params: dict[str, Any]) -> dict[str, Any]:
        expression = _string(params, "expression")
        if len(expression) > MAX_EXPRESSION:
            raise RpcError(INVALID_PARAMS, f"`expression` is longer than {MAX_EXPRESSION:,} "
                           "characters: give a value such as `U-L`")
        run = self._running_run()
        if run.busy:
            raise RpcError(RUNNING, "the program is running: pause it first")
        try:
            value = parse_value(expression).of(run.session.machine.variables)
        except DebugError as error:
            raise RpcError(INVALID_PARAMS, str(error)) from None
        return {"value": value}

    # The methods of spec/studio.md, each a coroutine of the connection and the params.
    METHODS: ClassVar[dict[str, Callable[[Connection, dict[str, Any]],
                                         Awaitable[dict[str, Any]]]]] = {
        "initialize": _initialize,
        "files/list": _list,
        "files/read": _read,
        "files/save": _save,
        "world/check": _check_world,
        "palette": _palette,
        "run/launch": _launch,
        "debug/setBreakpoints": _set_breakpoints,
        "debug/continue": _continue,
        "debug/stepLine": _step_line,
        "debug/stepInstruction": _step_instruction,
        "debug/pause": _pause,
        "debug/restart": _restart,
        "debug/stop": _stop,
        "debug/setSpeed": _set_speed,
        "debug/evaluate": _evaluate,
    }


# Params ------------------------------------------------------------------------------

def _is_id(value: object) -> bool:
    return isinstance(value, str | int | float) and not isinstance(value, bool)


def _whole(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _string(params: dict[str, Any], key: str) -> str:
    value = params.get(key)
    if not isinstance(value, str):
        raise RpcError(INVALID_PARAMS, f"`{key}` is {'missing' if value is None else repr(value)}"
                       ": give a string")
    return value


def _speed(params: dict[str, Any]) -> float | None:
    speed = params["speed"]
    if speed is None:
        return None
    if isinstance(speed, bool) or not isinstance(speed, int | float) or not (
            MIN_SPEED <= speed <= MAX_SPEED):
        raise RpcError(INVALID_PARAMS, f"`speed` is {reprlib.repr(speed)}: give a number of "
                       f"times real time, {MIN_SPEED:g} to {MAX_SPEED:g}, or null for the "
                       "fastest")
    return float(speed)


def _source(params: dict[str, Any], key: str, default_name: str) -> Source | None:
    """A launch's file: {"path": P} or {"text": T, "name": N}; None when not given."""
    given = params.get(key)
    if given is None:
        return None
    match given:
        case {"path": str(path)}:
            return Source(path, path=path)
        case {"text": str(text), **rest} if isinstance(name := rest.get("name", default_name),
                                                       str):
            if len(text) > MAX_FILE_BYTES:
                raise RpcError(FILE_UNUSABLE, f"`{key}` is larger than "
                               f"{MAX_FILE_BYTES // 2**20} MiB, the most the studio runs")
            if len(_unicode(name, f"`{key}.name`").encode()) > ilc.MAX_NAME_SIZE:
                raise RpcError(INVALID_PARAMS, f"`{key}.name` is longer than "
                               f"{ilc.MAX_NAME_SIZE} bytes, the most a program records: give "
                               "a file's name, such as `sample.rob`")
            return Source(name, text=_unicode(text, f"`{key}.text`"))
    raise RpcError(INVALID_PARAMS, f"`{key}` is {reprlib.repr(given)}: give {{\"path\": "
                   "\"a file in the folder\"} or {\"text\": \"...\", \"name\": \"...\"}")


def _recorded(name: str) -> str:
    """The name the program's debug section records: a path too long for it as its
    file's name, as `rl1c build` records it (a page's own name is refused in `_source`)."""
    return name if len(name.encode()) <= ilc.MAX_NAME_SIZE else PurePosixPath(name).name


def _unicode(value: str, what: str) -> str:
    """`value`, refused if it holds half of a surrogate pair: JSON can carry one (an
    escape such as `\\ud800`), which is no character, so that no file, and no text a
    run is given, holds it."""
    try:
        value.encode()
    except UnicodeEncodeError as error:
        raise RpcError(INVALID_PARAMS, f"{what} holds {value[error.start:error.end]!r}, half "
                       "of a surrogate pair, which is no character: send Unicode text") from None
    return value


async def _files(work: Awaitable[Any]) -> Any:
    """`work` on the folder, its refusals as JSON-RPC errors."""
    try:
        return await work
    except Refused as refused:
        raise RpcError(FILE_REFUSED, str(refused)) from None
    except Unusable as unusable:
        raise RpcError(FILE_UNUSABLE, str(unusable)) from None
    except Changed as changed:
        raise RpcError(CHANGED, str(changed)) from None


def _utf8(data: bytes, path: str) -> str:
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise RpcError(FILE_UNUSABLE, f"`{path}` is not UTF-8 text (byte {error.start}): "
                       "save it as UTF-8") from None


def _said(error: SourceError) -> str:
    return f"{error}" + (f"; {error.help}" if error.help else "")
