"""Hostile inputs for every `rl1c` command, and what each must still do.

Shared by tests/cli/test_hostile_inputs.py (a bounded run in the test command) and
bench/hostile_fuzz.py (a campaign as long as asked). `source_attack`, `ilc_attack` and
`world_attack` run the commands in-process on one input and return the problems found:
an internal error, an exit status the command does not document, output written by a
command that failed, a traceback on any stream; and for world files, a bad world not
refused with status 2 and a message naming the file. `cache_attack` damages the C
engine's build cache and runs `rl1c run --engine c` from it, in a process of its own.
`transport_attack` sends `rl1-lsp --tcp` or `--ws` (a `ServedLsp`, started once for many
inputs) hostile connections, then checks that a well-behaved client is still served.
`attack_with_test_file` runs `rl1c test` on a hostile test file beside files no test should
read (a FIFO, a link loop, /dev/zero); `vary_attack` a campaign with pictures and a
seeded run on a world with a hostile [vary] table and hostile --sweep arguments;
`new_attack` `rl1c new` into each kind of place; `output_attack` `--junit` and a
campaign's pictures onto inputs, folders, links and read-only files. Each also checks
that no input changed.
"""

from __future__ import annotations

import atexit
import base64
import collections
import contextlib
import functools
import hashlib
import json
import os
import re
import shutil
import socket
import stat
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from hypothesis import strategies as st

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.cli.project_template import FILES
from rl1.compiler.strategies import programs
from rl1.lsp.framing import MAX_MESSAGE
from rl1.lsp.transports import (
    BUSY,
    MAX_SESSIONS,
    MEMORY_IN_FLIGHT,
)
from rl1.vm import native
from rl1.vm.sim.world import WorldError, decode_world

from . import EXAMPLES, ROOT, SAMPLE, SAMPLE_SENSORS
from .cli import Result, rl1c
from .ilc import with_crc
from .memory import at_once, status_mib

# The exit statuses each command documents (docs/commands.md).
STATUSES = {
    "check": {0, 1, 2},
    "fmt": {0, 1, 2},
    "compile": {0, 1, 2},
    "run": {0, 1, 2, 10, 11, 12, 13},
    "dis": {0, 1, 2},
    "asm": {0, 1, 2},
    "sim": {0, 1, 2, 10, 11, 12, 13, 20},  # 20: the program ended but missed its goal
    "test": {0, 1, 2},
    "new": {0, 2},
}
BUDGET = "20000"  # instructions: a runaway input ends quickly


def _mutated(text: bytes, draw: st.DrawFn) -> bytes:
    data = bytearray(text)
    for _ in range(draw(st.integers(1, 8))):
        if not data:
            data += draw(st.binary(min_size=1, max_size=8))
            continue
        at = draw(st.integers(0, len(data) - 1))
        action = draw(st.sampled_from(["flip", "insert", "delete", "replace", "cut"]))
        if action == "flip":
            data[at] ^= 1 << draw(st.integers(0, 7))
        elif action == "insert":
            data[at:at] = draw(st.binary(min_size=1, max_size=16))
        elif action == "delete":
            del data[at:at + draw(st.integers(1, 16))]
        elif action == "replace":
            data[at] = draw(st.integers(0, 255))
        else:
            del data[at:]
    return bytes(data)


@st.composite
def hostile_sources(draw: st.DrawFn) -> bytes:
    """Arbitrary bytes, generated programs, and programs mutated byte by byte."""
    kind = draw(st.sampled_from(["bytes", "program", "mutated"]))
    if kind == "bytes":
        return draw(st.binary(max_size=400))
    program = draw(programs(max_lines=12)).encode("utf-8")
    return program if kind == "program" else _mutated(program, draw)


def _seed_ilc_files() -> list[bytes]:
    sample = (EXAMPLES / "sample.rob").read_text(encoding="utf-8")
    compiled = [compile_text(sample, "sample.rob", strip_debug=strip).output
                for strip in (False, True)]
    documents = [json.loads(group.read_text(encoding="utf-8"))
                 for group in sorted((ROOT / "spec" / "vectors").glob("*.json"))]
    vectors = [bytes.fromhex(vector[key]) for document in documents
               for vector in document.get("vectors", []) for key in ("ilc", "ilc_stripped")]
    verifier_files = [bytes.fromhex(file["ilc"]) for document in documents
                      for file in document.get("files", [])]
    return [data for data in compiled if data is not None] + vectors + verifier_files


SEED_ILC_FILES = _seed_ilc_files()


@st.composite
def hostile_ilc_files(draw: st.DrawFn) -> bytes:
    """Valid .ilc files (the sample's, the vectors') mutated, mostly with the CRC fixed
    so that the mutation reaches the verifier rather than stopping at the checksum."""
    data = _mutated(draw(st.sampled_from(SEED_ILC_FILES)), draw)
    return with_crc(data) if len(data) >= 12 and draw(st.integers(0, 4)) else data


def _problems(command: str, result: Result, written: Path | None) -> list[str]:
    found = []
    if result.exit_code not in STATUSES[command]:
        found.append(f"{command}: exit status {result.exit_code}")
    if b"internal error" in result.output_bytes or b"Traceback" in result.output_bytes:
        found.append(f"{command}: {result.output_bytes[-300:]!r}")
    if written is not None and result.exit_code != 0 and written.exists():
        found.append(f"{command}: failed with status {result.exit_code} but wrote {written}")
    return found


def source_attack(data: bytes, folder: Path) -> list[str]:
    """Every command that reads RL/I source, on `data`."""
    source, output = folder / "hostile.rob", folder / "hostile.ilc"
    source.write_bytes(data)
    output.unlink(missing_ok=True)
    found = _problems("check", rl1c("check", source), None)
    found += _problems("check", rl1c("check", "--format", "sarif", "-", stdin=data), None)
    found += _problems("fmt", rl1c("fmt", "--diff", source), None)
    found += _problems("fmt", rl1c("fmt", "-", stdin=data), None)
    found += _problems("check", rl1c("check", "--diff", "--format", "concise", "-",
                                     stdin=data), None)
    found += _problems("compile", rl1c(source, "-o", output), output)
    c_output = folder / "hostile.c"
    c_output.unlink(missing_ok=True)
    found += _problems("compile", rl1c(source, "--emit", "c", "-o", c_output), c_output)
    for engine in ("vm", "ast"):
        found += _problems("run", rl1c("run", source, "--engine", engine, "--budget", BUDGET),
                           None)
    # Last, as it rewrites the source.
    found += _problems("check", rl1c("check", "--fix", source), None)
    return found


def ilc_attack(data: bytes, folder: Path) -> list[str]:
    """The commands that read .ilc files, on `data`; `asm` on what `dis` printed must
    give the same bytes back."""
    binary, text, again = folder / "hostile.ilc", folder / "hostile.ils", folder / "again.ilc"
    binary.write_bytes(data)
    again.unlink(missing_ok=True)
    found = _problems("run", rl1c("run", binary, "--budget", BUDGET), None)
    shown = rl1c("dis", binary)
    found += _problems("dis", shown, None)
    if shown.exit_code == 0 and data[4:6] == bytes([1, 0]):  # the round trip is for 1.0
        text.write_text(shown.stdout, encoding="utf-8")
        built = rl1c("asm", text, "-o", again)
        found += _problems("asm", built, again)
        if built.exit_code != 0 or again.read_bytes() != data:
            found.append(f"asm(dis(x)) != x: {built.output_bytes[-300:]!r}")
    return found


# A short program that uses every part of the world: the floor and its lines (tracing,
# the camera looking down), the markers (looking level), the ultrasonic sensors, the
# motion and the odometry.
SIM_PROGRAM = b"""(CAM D); (SCN 0); (TRC 1); (MOV 12,12); (TIM 10); A=(IMG)
(CAM U); (SCN 2); B=(IMG); C=(ULT A); D=(ULT B); (INP 3); (FZI)
(TRC 0); (ROT 90); (STX 450); (MVI 3,3,40); E=(KYO); (MOV 2,2)
(END)
"""
SEED_WORLDS = [path.read_bytes() for path in sorted(EXAMPLES.glob("*.world.toml"))]
# Values that break naive code: not finite, huge, tiny, of the wrong type, degenerate
# polygons, deep nesting.
HOSTILE_VALUES = [
    "nan", "inf", "-inf", "1e308", "-1e308", "1e6", "-1e6", "0", "-0.0", "5e-324",
    "9" * 400, '"x"', "true", "[]", "{}", "[[0, 0], [0, 0], [0, 0]]",
    "[[0, 0], [1e6, 1e6]]", "[[0, 0], [1e6, 0], [1e6, 1e6], [0, 1e6]]", "[1e6, 1e6]",
    "[0, 0, 0, 0]", "[0, 0, 1024, 1024]", "[" * 600 + "]" * 600,
]


@st.composite
def hostile_worlds(draw: st.DrawFn) -> bytes:
    """Arbitrary bytes, the example worlds mutated byte by byte, and the example worlds
    with one value replaced by a hostile one."""
    kind = draw(st.sampled_from(["bytes", "mutated", "value"]))
    if kind == "bytes":
        return draw(st.binary(max_size=400))
    world = draw(st.sampled_from(SEED_WORLDS))
    if kind == "mutated":
        return _mutated(world, draw)
    assignments = list(re.finditer(rb"(?m)^(\s*[\w\"]+\s*=\s*)(.*?)(\s*(#.*)?)$", world))
    chosen = draw(st.sampled_from(assignments))
    value = draw(st.sampled_from(HOSTILE_VALUES)).encode()
    return world[:chosen.start(2)] + value + world[chosen.end(2):]


def world_attack(data: bytes, folder: Path) -> list[str]:
    """`rl1c sim` on the world file `data`, with pictures and JSON: a world the loader
    refuses must end with status 2 and a message naming the file, and write nothing."""
    world, program, picture = folder / "hostile.world.toml", folder / "run.rob", folder / "run.svg"
    world.write_bytes(data)
    program.write_bytes(SIM_PROGRAM)
    picture.unlink(missing_ok=True)
    result = rl1c("sim", program, "--world", world, "--svg", picture, "--format", "json",
                  "--budget", BUDGET)
    # A run that faulted still draws its picture (the fault is in it); a refused input
    # draws none.
    found = _problems("sim", result, picture if result.exit_code in (1, 2) else None)
    try:
        decode_world(data, str(world))
    except WorldError:
        said = "error[E0100]: the world file is not valid: "
        if result.exit_code != 2 or not result.stderr.startswith(said):
            found.append(f"sim: a bad world gave status {result.exit_code}: "
                         f"{result.output_bytes[-300:]!r}")
    return found


# The C engine's build cache --------------------------------------------------------------


@functools.cache
def _built_cache() -> tuple[Path, bytes, str]:
    """A cache folder with the C VM built in it, the library's bytes, and what
    `rl1c run --engine c` prints from it (the first call builds: seconds)."""
    cache = Path(tempfile.mkdtemp(prefix="rl1-hostile-cache-"))
    atexit.register(shutil.rmtree, cache, ignore_errors=True)
    library = native.library(cache / "rl1")
    done = _run_engine_c(cache)
    assert done.returncode == 0 and "rl1: warning" not in done.stderr, done.stderr
    return cache, library.read_bytes(), done.stdout


def _run_engine_c(cache: Path) -> subprocess.CompletedProcess[str]:
    rl1c_path = Path(sys.executable).with_name("rl1c")
    return subprocess.run([str(rl1c_path), "run", str(SAMPLE), "--sensors",
                           str(SAMPLE_SENSORS), "--engine", "c", "--format", "json"],
                          capture_output=True, text=True, check=False, timeout=600,
                          env={**os.environ, "XDG_CACHE_HOME": str(cache)})


@st.composite
def hostile_libraries(draw: st.DrawFn) -> bytes:
    """Bytes for the cached library in place of the one built: the built one mutated
    (truncated, flipped, cut), arbitrary bytes, nothing."""
    kind = draw(st.sampled_from(["mutated", "mutated", "bytes", "empty"]))
    if kind == "bytes":
        return draw(st.binary(max_size=4096))
    return b"" if kind == "empty" else _mutated(_built_cache()[1], draw)


def cache_attack(data: bytes, folder: Path) -> list[str]:
    """`rl1c run --engine c` (in a process of its own: a bad library could kill it) from
    a copy of a built cache whose library now holds `data`: it must print what it
    printed from the intact cache, with a warning when the library was damaged, and
    leave an intact library behind."""
    cache, library_bytes, expected = _built_cache()
    copy = Path(tempfile.mkdtemp(dir=folder)) / "cache"  # a folder may serve many inputs
    shutil.copytree(cache, copy)
    library = next((copy / "rl1").glob("librl1vm-*.so"))
    library.write_bytes(data)
    done = _run_engine_c(copy)
    found = []
    if done.returncode != 0 or done.stdout != expected:
        found.append(f"run --engine c from a damaged cache: exit status {done.returncode}: "
                     f"{done.stderr[-300:]!r}")
    if "Traceback" in done.stderr or "internal error" in done.stderr:
        found.append(f"run --engine c: {done.stderr[-300:]!r}")
    if data != library_bytes and "is damaged or was not built there" not in done.stderr:
        found.append("run --engine c: no warning of the damaged library")
    recorded = library.with_name(library.name + native.DIGEST_SUFFIX)
    if recorded.read_text("ascii").strip() != hashlib.sha256(library.read_bytes()).hexdigest():
        found.append("run --engine c: the library left in the cache is not intact")
    return found


# The language server over TCP and WebSocket ----------------------------------------------

LSP_SERVER = [sys.executable, "-m", "rl1.lsp"]
PROBE_SECONDS = 15.0
"""How long the well-behaved client after each input waits for each answer (a few seconds
on an idle machine; more on a loaded one, before a hung server is called hung)."""
GROWTH_BOUND_MIB = MEMORY_IN_FLIGHT // 2**20 + 64
"""How far the server's resident memory may grow past what it held once started, at its
peak: what its messages in flight may take (transports.MEMORY_IN_FLIGHT, all sessions
together), and what the allocator keeps."""
SECRET = "file:///hostile/secret.rob"
"""The document every hostile connection opens: no other session may hear of it."""
WS_GUID = b"258EAFA5-E914-47DA-95CA-C5AB0DC85B11"


def _frame(message: object) -> bytes:
    body = message if isinstance(message, bytes) else json.dumps(message).encode()
    return b"Content-Length: %d\r\n\r\n" % len(body) + body


def _lsp(msg_id: int | None, method: str, params: object) -> dict[str, object]:
    message: dict[str, object] = {"jsonrpc": "2.0", "method": method, "params": params}
    return message if msg_id is None else {**message, "id": msg_id}


INITIALIZE = _lsp(1, "initialize", {"processId": None, "rootUri": None, "capabilities": {}})
OPEN_SECRET = _lsp(None, "textDocument/didOpen", {"textDocument": {
    "uri": SECRET, "languageId": "rl1", "version": 1, "text": "A=(  ' secret\n"}})


class ServedLsp:
    """`rl1-lsp --tcp` or `--ws` on a free port of 127.0.0.1, in a process of its own."""

    def __init__(self, transport: str) -> None:
        self.transport = transport
        self.start()

    def start(self) -> None:
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            self.port: int = probe.getsockname()[1]
        self.process = subprocess.Popen(
            [*LSP_SERVER, f"--{self.transport}", f"127.0.0.1:{self.port}"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        self.said: collections.deque[str] = collections.deque(maxlen=40)
        self.tracebacks: list[str] = []
        # Read standard error as it comes, lest a full pipe stop the server's logging.
        threading.Thread(target=self._read_stderr, args=(self.process.stderr,),
                         daemon=True).start()
        deadline = time.monotonic() + 60
        while self.process.poll() is None and time.monotonic() < deadline:
            with contextlib.suppress(OSError), socket.create_connection(
                    ("127.0.0.1", self.port), timeout=1):
                break
            time.sleep(0.1)
        self.started_mib = self.resident_mib()

    def resident_mib(self) -> float:
        """Resident memory, from /proc (0 once the process has ended)."""
        with contextlib.suppress(OSError):
            return status_mib(self.process.pid, "VmRSS")
        return 0.0

    def peak_mib(self) -> float:
        """The most resident memory the process has held, from /proc."""
        return status_mib(self.process.pid, "VmHWM")

    def _read_stderr(self, stream: IO[bytes]) -> None:
        with stream:
            for line in stream:
                text = line.decode(errors="replace")
                self.said.append(text)
                if "Traceback" in text:
                    self.tracebacks.append("")
                if self.tracebacks and len(self.tracebacks[-1]) < 3000:
                    self.tracebacks[-1] += text

    def stop(self) -> str:
        """Ends the server; returns the last lines it wrote on standard error."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(30)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        return "".join(self.said)


@dataclass(frozen=True)
class HostileConnection:
    """What one hostile connection sends: `chunks` in order (on a WebSocket, after the
    opening handshake, raw frames), then maybe half-closes its end (`half_close`);
    `copies` such connections at once, each kept open while the next input's
    well-behaved client is served when they leave it a place."""

    chunks: tuple[bytes, ...]
    half_close: bool = False
    copies: int = 1
    origin: str | None = None
    handshake: bytes | None = None  # on a WebSocket, sent for the opening handshake


def _json_values() -> st.SearchStrategy[object]:
    return st.recursive(
        st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=20),
        lambda inner: st.lists(inner, max_size=4) | st.dictionaries(
            st.text(max_size=10), inner, max_size=4), max_leaves=12)


LSP_METHODS = ["initialize", "textDocument/didOpen", "textDocument/didChange",
               "textDocument/hover", "textDocument/completion", "textDocument/codeAction",
               "textDocument/formatting", "textDocument/rename", "shutdown", "exit",
               "$/cancelRequest", "workspace/didChangeConfiguration", "no/such/method"]


@st.composite
def _hostile_bodies(draw: st.DrawFn) -> bytes:
    """Message bodies: nested or malformed JSON, JSON that is no message, valid LSP with
    hostile parameters, documents of hostile source."""
    kind = draw(st.sampled_from(["nested", "malformed", "json", "params", "document"]))
    if kind == "nested":
        depth = draw(st.integers(100, 5000))
        return draw(st.sampled_from([b"[", b'{"a":', b'{"jsonrpc":"2.0","params":['])) * depth
    if kind == "malformed":
        return _mutated(json.dumps(INITIALIZE).encode(), draw)
    if kind == "json":
        return json.dumps(draw(_json_values())).encode()
    if kind == "params":
        msg_id = draw(st.none() | st.integers(-2**63, 2**63) | st.text(max_size=8))
        return json.dumps(_lsp(msg_id, draw(st.sampled_from(LSP_METHODS)),  # type: ignore[arg-type]
                               draw(_json_values()))).encode()
    text = draw(hostile_sources()).decode("utf-8", errors="replace")
    return json.dumps(_lsp(None, "textDocument/didOpen", {"textDocument": {
        "uri": SECRET, "languageId": "rl1", "version": draw(st.integers()),
        "text": text}})).encode()


@st.composite
def _hostile_stream(draw: st.DrawFn) -> tuple[bytes, ...]:
    """What a hostile client writes on a byte stream (TCP): broken headers, lying or huge
    Content-Lengths, hostile bodies, after an initialize and the secret document or not."""
    start = (_frame(INITIALIZE) + _frame(OPEN_SECRET),) if draw(st.booleans()) else ()
    body = draw(_hostile_bodies())
    kind = draw(st.sampled_from(["framed", "lie", "header", "bomb", "bytes"]))
    if kind == "framed":
        return (*start, _frame(body))
    if kind == "lie":
        told = max(0, len(body) + draw(st.integers(-len(body), 4096)))
        return (*start, b"Content-Length: %d\r\n\r\n" % told + body)
    if kind == "header":
        header = draw(st.sampled_from([
            b"Content-Length: -1", b"Content-Length: 1e3", b"Content-Length: 0x10",
            b"Content-Length: " + b"9" * 5000, b"Content-Length: 99999999999",
            b"Content-Length: 5\r\nContent-Length: 7", b"X: " + b"y" * 200_000,
            b"Content-Type: \xff\xfe", b"content-length:" + b" " * 9000 + b"3", b"",
            b"\r\n" * 1000, b"Content-Length: 3\n"]))
        return (*start, header + b"\r\n\r\n" + body)
    if kind == "bomb":  # a huge length, then data streamed: read in bounded memory
        mebibytes = draw(st.integers(1, 24))
        return (*start, b"Content-Length: 99999999999\r\n\r\n",
                *([b"[" * 2**20] * mebibytes))
    return (*start, draw(st.binary(max_size=2000)))


def ws_frame(opcode: int, payload: bytes, fin: bool = True, masked: bool = True,
              told: int | None = None) -> bytes:
    """One WebSocket frame as a client sends it (RFC 6455 5.2); `told` lies about the
    payload's length."""
    length = len(payload) if told is None else told
    head = bytes([(0x80 if fin else 0) | opcode])
    mask_bit = 0x80 if masked else 0
    if length < 126:
        head += bytes([mask_bit | length])
    elif length < 2**16:
        head += bytes([mask_bit | 126]) + length.to_bytes(2, "big")
    else:
        head += bytes([mask_bit | 127]) + length.to_bytes(8, "big")
    if not masked:
        return head + payload
    mask = os.urandom(4)
    repeated = (mask * (len(payload) // 4 + 1))[:len(payload)]
    hidden = int.from_bytes(payload, "big") ^ int.from_bytes(repeated, "big")
    return head + mask + hidden.to_bytes(len(payload), "big")


@st.composite
def _hostile_frames(draw: st.DrawFn) -> tuple[bytes, ...]:
    """What a hostile client writes after the opening handshake: frames of the wrong type,
    oversize, fragmented, unmasked, lying about their length, of hostile bodies."""
    start = ((ws_frame(1, json.dumps(INITIALIZE).encode()),
              ws_frame(1, json.dumps(OPEN_SECRET).encode())) if draw(st.booleans()) else ())
    body = draw(_hostile_bodies())
    kind = draw(st.sampled_from(["text", "binary", "opcode", "fragments", "unmasked",
                                 "oversize", "lie", "control", "bytes"]))
    if kind == "text":
        return (*start, ws_frame(1, body))
    if kind == "binary":
        return (*start, ws_frame(2, body))
    if kind == "opcode":  # reserved opcodes, a continuation with nothing to continue
        return (*start, ws_frame(draw(st.sampled_from([0, 3, 7, 11, 15])), body))
    if kind == "fragments":
        cuts = sorted(draw(st.lists(st.integers(0, len(body)), max_size=6)))
        pieces = [body[a:b] for a, b in zip([0, *cuts], [*cuts, len(body)], strict=True)]
        frames = [ws_frame(1 if i == 0 else 0, piece, fin=i == len(pieces) - 1)
                  for i, piece in enumerate(pieces)]
        if draw(st.booleans()):  # a ping between fragments is allowed; a text frame is not
            frames.insert(draw(st.integers(0, len(frames))),
                          ws_frame(draw(st.sampled_from([1, 9])), b"x"))
        return (*start, *frames)
    if kind == "unmasked":
        return (*start, ws_frame(1, body, masked=False))
    if kind == "oversize":  # over the message limit, as a frame or in fragments
        told = draw(st.sampled_from([MAX_MESSAGE + 1, 2**32, 2**63 - 1]))
        if draw(st.booleans()):
            return (*start, ws_frame(1, b"[" * 2**20, told=told))
        piece = b"[" * (MAX_MESSAGE // 4 + 1)
        return (*start, ws_frame(1, piece, fin=False), *[ws_frame(0, piece, fin=False)] * 4)
    if kind == "lie":
        return (*start, ws_frame(1, body, told=len(body) + draw(st.integers(1, 4096))))
    if kind == "control":  # a control frame too long, fragmented, or a bad close
        return (*start, draw(st.sampled_from([
            ws_frame(9, b"p" * 200), ws_frame(9, b"p", fin=False),
            ws_frame(8, b"\x00\x01"), ws_frame(8, b"\x03\xe8\xff"), ws_frame(8, b"x")])))
    return (*start, draw(st.binary(max_size=2000)))


@st.composite
def hostile_connections(draw: st.DrawFn, transport: str) -> HostileConnection:
    """Hostile clients of `rl1-lsp --tcp` (transport "tcp") or `--ws` ("ws")."""
    chunks = draw(_hostile_stream() if transport == "tcp" else _hostile_frames())
    origin, handshake = None, None
    if transport == "ws":
        origin = draw(st.sampled_from([None, None, "http://localhost:8000",
                                       "https://evil.example", "null", "http://127.0.0.1.evil"]))
        handshake = draw(st.none() | st.none() | st.none() | _hostile_requests())
    return HostileConnection(chunks=chunks, half_close=draw(st.booleans()),
                             copies=draw(st.sampled_from([1, 1, 1, 2, 7, 12])), origin=origin,
                             handshake=handshake)


@st.composite
def _hostile_requests(draw: st.DrawFn) -> bytes:
    """An opening request a WebSocket server cannot read, or one mutated byte by byte."""
    if draw(st.booleans()):
        request, _ = draw(st.sampled_from(list(UNREADABLE_REQUESTS.values())))
        return request
    return _mutated(ws_handshake(0, None), draw)


def ws_handshake(port: int, origin: str | None) -> bytes:
    key = base64.b64encode(os.urandom(16))
    lines = [b"GET / HTTP/1.1", b"Host: 127.0.0.1:%d" % port, b"Upgrade: websocket",
             b"Connection: Upgrade", b"Sec-WebSocket-Key: " + key,
             b"Sec-WebSocket-Version: 13"]
    if origin is not None:
        lines.append(b"Origin: " + origin.encode())
    return b"\r\n".join(lines) + b"\r\n\r\n"


UNREADABLE_REQUESTS: dict[str, tuple[bytes, int]] = {
    "a body": (b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 5\r\n\r\nhello", 400),
    "a chunked body": (b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked"
                       b"\r\n\r\n0\r\n\r\n", 400),
    "not ASCII": ("GET /\u00e9 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode(), 400),
    "no request line": (b"hello\r\n\r\n", 400),
    "HTTP/2.0": (b"GET / HTTP/2.0\r\nHost: 127.0.0.1\r\n\r\n", 400),
    "a header line without a colon": (b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nno colon"
                                      b"\r\n\r\n", 400),
    "a header line too long": (b"GET / HTTP/1.1\r\nX: " + b"y" * 9000 + b"\r\n\r\n", 431),
    "too many headers": (b"GET / HTTP/1.1\r\n" + b"X: y\r\n" * 200 + b"\r\n", 431),
    "a request line too long": (b"GET /" + b"a" * 9000 + b" HTTP/1.1\r\n\r\n", 414),
}
"""Requests that a WebSocket server here (its library) cannot read as HTTP, and the
status each is answered with."""


def http_answer(port: int, request: bytes) -> tuple[int, str]:
    """The status and body with which the server on `port` answers `request`, sent as it
    is; (0, "") when it closes the connection without an answer."""
    with socket.create_connection(("127.0.0.1", port), timeout=30) as client:
        client.sendall(request)
        received = b""
        while chunk := client.recv(65536):
            received += chunk
    if not received:
        return 0, ""
    head, _, body = received.partition(b"\r\n\r\n")
    return int(head.split(b" ", 2)[1]), body.decode()


def _send_hostile(server: ServedLsp, attack: HostileConnection) -> socket.socket | None:
    """Open one hostile connection and send what it sends; None when the server closed
    it or it timed out on the way (the server may refuse anything)."""
    try:
        connection = socket.create_connection(("127.0.0.1", server.port), timeout=5)
    except OSError:
        return None
    try:
        if server.transport == "ws":
            connection.sendall(attack.handshake or ws_handshake(server.port, attack.origin))
        for chunk in attack.chunks:
            connection.sendall(chunk)
        if attack.half_close:
            connection.shutdown(socket.SHUT_WR)
        return connection
    except OSError:
        connection.close()
        return None


class _Probe:
    """The well-behaved client: initialize, open a small document, get its diagnostics,
    and hear nothing of any other session's documents."""

    def __init__(self, server: ServedLsp) -> None:
        self.server = server
        self.heard: list[dict[str, Any]] = []

    def run(self) -> str | None:
        """None when served, else what went wrong. A refusal because the server serves
        as many clients as it may is tried again (the hostile ones' places are freed
        when the server reads their end)."""
        deadline = time.monotonic() + PROBE_SECONDS
        while (said := self._once()) == BUSY and time.monotonic() < deadline:
            time.sleep(0.2)
        return said

    def _once(self) -> str | None:
        uri = f"file:///probe/{os.urandom(4).hex()}.rob"
        opened = _lsp(None, "textDocument/didOpen", {"textDocument": {
            "uri": uri, "languageId": "rl1", "version": 1, "text": "A=(  ' unclosed\n"}})
        try:
            if self.server.transport == "tcp":
                return self._over_tcp(uri, opened)
            return self._over_websocket(uri, opened)
        except ConnectionResetError:  # closed at once: as many refused as it may refuse
            return BUSY
        except (OSError, TimeoutError, ValueError) as error:
            return f"the next client was not served: {type(error).__name__}: {error}"

    def _check(self, message: dict[str, Any], uri: str) -> str | None:
        """None while waiting for more; "" when served; else what went wrong."""
        self.heard.append(message)
        if SECRET in json.dumps(message):
            return f"the next client heard another session's document: {message}"
        if message.get("id") == 1 and message.get("error", {}).get("message") == BUSY:
            return BUSY
        if message.get("id") == 1 and "result" not in message:
            return f"the next client's initialize was not answered: {message}"
        if message.get("method") == "textDocument/publishDiagnostics":
            params = message["params"]
            if params["uri"] != uri:
                return f"the next client got diagnostics of another document: {params}"
            return "" if params["diagnostics"] else f"no diagnostics for {uri}"
        return None

    def _over_tcp(self, uri: str, opened: dict[str, object]) -> str | None:
        with socket.create_connection(("127.0.0.1", self.server.port),
                                      timeout=PROBE_SECONDS) as client:
            client.sendall(_frame(INITIALIZE) + _frame(_lsp(None, "initialized", {}))
                           + _frame(opened))
            buffer = b""
            deadline = time.monotonic() + PROBE_SECONDS
            while time.monotonic() < deadline:
                head, found, rest = buffer.partition(b"\r\n\r\n")
                length = int(head.split(b":")[1]) if found else -1
                if 0 <= length <= len(rest):
                    buffer = rest[length:]
                    if (said := self._check(json.loads(rest[:length]), uri)) is not None:
                        return said or None
                    continue
                chunk = client.recv(65536)
                if not chunk:  # closed at once, as above, or closed after something said
                    return BUSY if not self.heard else (
                        f"the server closed the next client's connection: {self.heard}")
                buffer += chunk
        return f"the next client got no diagnostics in {PROBE_SECONDS:.0f} s: {self.heard}"

    def _over_websocket(self, uri: str, opened: dict[str, object]) -> str | None:
        from websockets.exceptions import WebSocketException
        from websockets.sync.client import connect

        try:
            with connect(f"ws://127.0.0.1:{self.server.port}",
                         open_timeout=PROBE_SECONDS) as client:
                for message in (INITIALIZE, _lsp(None, "initialized", {}), opened):
                    client.send(json.dumps(message))
                deadline = time.monotonic() + PROBE_SECONDS
                while (left := deadline - time.monotonic()) > 0:
                    if (said := self._check(json.loads(client.recv(left)), uri)) is not None:
                        return said or None
        except WebSocketException as error:
            if getattr(getattr(error, "rcvd", None), "code", None) == 1013:  # try again later
                return BUSY
            return f"the next client was not served: {type(error).__name__}: {error}"
        return f"the next client got no diagnostics in {PROBE_SECONDS:.0f} s: {self.heard}"


def serve_one_after_another(server: ServedLsp, clients: int) -> None:
    """Serve `clients` well-behaved clients (as after each hostile input), each leaving
    before the next comes; AssertionError when one is not served."""
    for _ in range(clients):
        if (said := _Probe(server).run()) is not None:
            raise AssertionError(f"{server.transport}: {said[:300]}")


LARGE_INITIALIZE = ('{"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": '
                    '{"capabilities": {}, "rootPath": "' + "\\u0041" * (10 * 2**20) + '"}}')
"""An initialize of 60 MiB: JSON escapes of 10 MiB of text."""


def large_messages_at_once(server: ServedLsp, clients: int = MAX_SESSIONS) -> list[str]:
    """`clients` WebSocket clients sending LARGE_INITIALIZE to `server` at once: the
    answers they were given (a client refused while the others' are read, by a
    WebSocketException or an OSError, has none)."""
    from websockets.exceptions import WebSocketException
    from websockets.sync.client import connect

    answered: list[str] = []

    def send() -> None:
        with contextlib.suppress(WebSocketException, OSError), connect(
                f"ws://127.0.0.1:{server.port}", max_size=None, open_timeout=60) as client:
            client.send(LARGE_INITIALIZE)
            answered.append(str(client.recv(timeout=60)))

    at_once(clients, send)
    return answered


def transport_attack(server: ServedLsp, attack: HostileConnection) -> list[str]:
    """The hostile connections of `attack`, then a well-behaved client, which must be
    served (initialize answered, diagnostics of its document within PROBE_SECONDS, nothing
    of another session's documents) while the server's memory stays within
    GROWTH_BOUND_MIB of what it started with. A server found dead is started again."""
    hostile = [_send_hostile(server, attack) for _ in range(attack.copies)]
    try:
        if len(hostile) >= MAX_SESSIONS:  # they hold the places: the probe comes after
            for connection in hostile:
                if connection is not None:
                    connection.close()
        found = []
        if (said := _Probe(server).run()) is not None:
            found.append(f"{server.transport}: {said[:300]}")
    finally:
        for connection in hostile:
            if connection is not None:
                connection.close()
    if (grown := server.resident_mib() - server.started_mib) > GROWTH_BOUND_MIB:
        found.append(f"{server.transport}: the server grew by {grown:.0f} MiB")
    if server.tracebacks:
        found.append(f"{server.transport}: a traceback: {server.tracebacks[0][-600:]!r}")
        server.tracebacks.clear()
    if server.process.poll() is not None:
        found.append(f"{server.transport}: the server ended with status "
                     f"{server.process.returncode}: {server.stop()[-300:]!r}")
        server.start()
    elif found:  # start afresh, so that one problem is not counted again and again
        server.stop()
        server.start()
    return found


# Program tests, [vary] and sweeps, campaigns' outputs, rl1c new ------------------------

PROJECT = {name: text.encode() for name, text in FILES.items()}
"""`rl1c new`'s files: a program, a world with a goal, a sensor script, a test file."""
HOSTILE_PATHS = [
    "fifo.rob", "loop.rob", "folder.rob", "zero.rob", "missing.rob", "/dev/zero",
    "../main.rob", ".", "a\\u0000b.rob", "x" * 5000, "main.world.toml", "main.tests.toml",
    "main.sensors.toml", "main.rob", "main.rob/", "hostile.ilc"]
"""Paths a hostile test file names, as TOML writes them; what the special ones are is
`_project`'s."""
MAX_HOSTILE_RUNS = 60  # of a success rate the harness runs (a mutation may ask 100,000)


def _project(folder: Path) -> Path:
    """`folder`/project with `rl1c new`'s files and files no test should read: a FIFO,
    a symbolic link loop, a folder, a link to /dev/zero and a damaged .ilc file."""
    project = folder / "project"
    if not project.exists():
        project.mkdir()
        for name, data in PROJECT.items():
            (project / name).parent.mkdir(parents=True, exist_ok=True)
            (project / name).write_bytes(data)
        os.mkfifo(project / "fifo.rob")
        (project / "loop.rob").symlink_to("loop.rob")
        (project / "folder.rob").mkdir()
        (project / "zero.rob").symlink_to("/dev/zero")
        (project / "hostile.ilc").write_bytes(SEED_ILC_FILES[0][:40])
    return project


def _contents(folder: Path) -> dict[str, bytes | str]:
    """Every entry under `folder` (links not followed): a regular file's bytes, else what
    it is; so that a command that must change nothing can be held to it."""
    found: dict[str, bytes | str] = {}
    for path in sorted(folder.rglob("*")):
        mode = path.lstat().st_mode
        name = str(path.relative_to(folder))
        found[name] = path.read_bytes() if stat.S_ISREG(mode) else (
            f"link to {os.readlink(path)}" if stat.S_ISLNK(mode) else stat.filemode(mode))
    return found


def _toml_string(text: str) -> str:
    return '"' + text.replace('"', '\\"') + '"'


def _replace_value(draw: st.DrawFn, document: bytes, values: list[str]) -> bytes:
    """`document` with the value of one of its `key = value` lines replaced by one of
    `values`."""
    assignments = list(re.finditer(rb"(?m)^(\s*[\w.\"]+\s*=\s*)(.*?)(\s*(#.*)?)$", document))
    chosen = draw(st.sampled_from(assignments))
    value = draw(st.sampled_from(values)).encode()
    return document[:chosen.start(2)] + value + document[chosen.end(2):]


@st.composite
def hostile_test_files(draw: st.DrawFn) -> bytes:
    """Arbitrary bytes; `rl1c new`'s test file and the examples' mutated byte by byte,
    with a value replaced by a hostile one or a hostile path, or with a hostile key."""
    kind = draw(st.sampled_from(["bytes", "mutated", "value", "path", "key"]))
    if kind == "bytes":
        return draw(st.binary(max_size=400))
    seed = draw(st.sampled_from([PROJECT["main.tests.toml"],
                                 (EXAMPLES / "listing1.tests.toml").read_bytes()]))
    match kind:
        case "mutated":
            return _mutated(seed, draw)
        case "value":
            return _replace_value(draw, seed, HOSTILE_VALUES)
        case "path":
            return _replace_value(draw, seed, [_toml_string(path) for path in HOSTILE_PATHS])
    line = draw(st.sampled_from([
        b"expect.nope = 1", b"test = 5", b"[[test.expect]]", b"[test]", b"nope = 1",
        b'expect.calls = ["MOV 99999999999,1", "CAM", ""]', b"expect.variables = { AA = 1 }",
        b"expect.success = { runs = 0, at_least = 2 }", b"seed = 4294967295",
        b"expect = 5", b'engine = "ast"', b'world = "main.world.toml"', b'name = ""']))
    return seed + b"\n" + line + b"\n"


def attack_with_test_file(data: bytes, folder: Path) -> list[str]:
    """`rl1c test` on the test file `data` in a project with hostile neighbours (a FIFO,
    a link loop, /dev/zero...), with --junit: a file the loader refuses must end with
    status 2 and a message naming it, before any test runs; no input may change; a
    JUnit file is written only when the tests ran."""
    from rl1.compiler.test_file import Success, load_test_file
    from rl1.vm.config import ConfigError

    project = _project(folder)
    tests, junit = project / "hostile.tests.toml", folder / "report.xml"
    tests.write_bytes(data)
    junit.unlink(missing_ok=True)
    before = _contents(project)
    try:
        loaded = load_test_file(data, str(tests)).test
    except ConfigError:
        loaded = None
    if loaded is not None and any(isinstance(test.expect.success, Success)
                                  and test.expect.success.runs > MAX_HOSTILE_RUNS
                                  for test in loaded):
        return []  # valid, and too long to run here
    result = rl1c("test", tests, "--jobs", "1", "--junit", junit)
    found = _problems("test", result, junit if result.exit_code == 2 else None)
    if loaded is None and (result.exit_code != 2 or result.stdout or not result.stderr
                           .startswith("error[E0100]: the test file is not valid: ")):
        found.append(f"test: a bad test file gave status {result.exit_code}: "
                     f"{result.output_bytes[-300:]!r}")
    if loaded is not None and result.exit_code in (0, 1) and not junit.exists():
        found.append(f"test: status {result.exit_code} without the JUnit file")
    if _contents(project) != before:
        found.append("test: an input of the tests changed")
    return found


VARY_KEYS = [
    "start.x", "start.y", "start.heading", "stands.stand.x", "stands.stand.facing",
    "stands.nope.y", "vehicle.tread", "vehicle.trace_interval", "vehicle.camera_fov",
    "vehicle.tilt_down", "vehicle.rotate_speed", "vehicle.nope", "noise.slip",
    "noise.image_px", "noise.nope", "start", "nope.x", "start.x.y", '"start.x"']
HOSTILE_NUMBERS = ["0", "-0.0", "1", "-1", "5", "-5", "0.001", "1e6", "-1e6", "1e7", "nan",
                   "inf", "-inf", "5e-324", "1e-300", "9" * 400, '"x"', "[]", "true"]
"""Numbers (and not) where a [vary] distribution or a --sweep wants one."""


@st.composite
def _distributions(draw: st.DrawFn) -> str:
    number = st.sampled_from(HOSTILE_NUMBERS)
    kind = draw(st.sampled_from(["plausible", "plausible", "plausible", "uniform", "normal",
                                 "within", "both", "odd"]))
    pair = f"[{draw(number)}, {draw(number)}]"
    match kind:
        case "plausible":  # mostly valid, so that the runs are reached
            spread = draw(st.sampled_from(["0", "0.001", "0.5", "1", "5", "50"]))
            return draw(st.sampled_from([
                f"{{ uniform = [-{spread}, {spread}] }}", f"{{ uniform = [0, {spread}] }}",
                f"{{ normal = [0, {spread}] }}",
                f"{{ normal = [0, {spread}], within = [-{spread}, {spread}] }}"]))
        case "uniform":
            return f"{{ uniform = {pair} }}"
        case "normal":
            return f"{{ normal = {pair} }}"
        case "within":
            return f"{{ normal = {pair}, within = [{draw(number)}, {draw(number)}] }}"
        case "both":
            return f"{{ uniform = {pair}, normal = {pair} }}"
    return draw(st.sampled_from(
        ["{ }", "{ uniform = [0, 1], within = [0, 1] }", "{ x = 1 }", "{ uniform = [0] }",
         "{ normal = [0, 1, 2] }", *HOSTILE_VALUES]))


@st.composite
def hostile_vary_worlds(draw: st.DrawFn) -> bytes:
    """A world (the examples', `rl1c new`'s) with a [vary] table of hostile entries:
    keys naming nothing, distributions inverted, not finite, of sd 0, with bounds
    outside the value's range, of the wrong type."""
    world = draw(st.sampled_from([*SEED_WORLDS, PROJECT["main.world.toml"]]))
    key = st.one_of(st.sampled_from(VARY_KEYS[:6]), st.sampled_from(VARY_KEYS))
    entries = draw(st.lists(st.tuples(key, _distributions()), min_size=1, max_size=3,
                            unique_by=lambda entry: entry[0].split(".")[0]))
    return world + b"\n[vary]\n" + "".join(f"{key} = {value}\n"
                                           for key, value in entries).encode()


@st.composite
def hostile_sweeps(draw: st.DrawFn) -> tuple[str, ...]:
    """`--sweep` arguments: none to three, of keys naming nothing or swept twice, of
    offsets not finite or out of range, of counts zero, padded or huge, or not
    KEY=A:B:N at all."""
    offset = st.sampled_from(["0", "1", "-1", "-5", "5", "1e6", "nan", "inf", "x", ""])
    count = st.sampled_from(["1", "2", "3", "0", "002", "10001", "9" * 30, "", "-1", "2.5"])
    axis = st.builds(lambda key, a, b, n: f"{key}={a}:{b}:{n}", st.sampled_from(VARY_KEYS),
                     offset, offset, count)
    junk = st.sampled_from(["", "=", "start.x", "start.x=1:2", "start.x==1:2:3",
                            "start.x=1:2:3:4", "=0:1:2", " start.x = 0 : 1 : 2 "])
    return tuple(draw(st.lists(st.one_of(axis, axis, junk), max_size=3)))


def vary_attack(world_data: bytes, sweeps: tuple[str, ...], folder: Path) -> list[str]:
    """`rl1c sim` on the world `world_data` with `sweeps`: a campaign with its pictures
    and JSON lines, and the one run of a seed. A world the loader refuses ends with
    status 2 and a message naming it; a campaign that did not run writes nothing."""
    world, program = folder / "hostile.world.toml", folder / "run.rob"
    outputs = [folder / "runs.svg", folder / "runs.html", folder / "runs.jsonl"]
    world.write_bytes(world_data)
    program.write_bytes(SIM_PROGRAM)
    for output in outputs:
        output.unlink(missing_ok=True)
    sweep_options = [word for text in sweeps for word in ("--sweep", text)]
    campaign = rl1c("sim", program, "--world", world, "--runs", "2", "--jobs", "1",
                    "--budget", BUDGET, "--svg", outputs[0], "--html", outputs[1],
                    "--out", outputs[2], *sweep_options)
    found = _problems("sim", campaign, None)
    if campaign.exit_code != 0:
        found += [f"sim --runs: failed with status {campaign.exit_code} but wrote {output}"
                  for output in outputs if output.exists()]
    one_run = rl1c("sim", program, "--world", world, "--seed", "1", "--format", "json",
                   "--budget", BUDGET, *sweep_options)
    found += _problems("sim", one_run, None)
    try:
        decode_world(world_data, str(world))
    except WorldError:
        said = "error[E0100]: the world file is not valid: "
        for result in (campaign, one_run):
            if result.exit_code != 2 or not result.stderr.startswith(said):
                found.append(f"sim: a bad world gave status {result.exit_code}: "
                             f"{result.output_bytes[-300:]!r}")
    return found


NEW_TARGETS = ["missing", "empty", "link-to-empty", "file", "link-to-file", "dangling-link",
               "link-loop", "not-empty", "hidden-file", "fifo", "under-a-file",
               "missing-parent", "dash"]
"""What `rl1c new` is given: the first three are a project's place, the rest refused."""


def new_attack(kind: str, folder: Path) -> list[str]:
    """`rl1c new` into the target `kind` of NEW_TARGETS, made in `folder`: a new or empty
    folder gets the whole project (status 0); anything else status 2 and no change at
    all, not even a temporary folder left behind."""
    place = folder / "place"
    place.mkdir()
    (place / "kept.txt").write_text("kept")
    target = place / "project"
    match kind:
        case "empty":
            target.mkdir()
        case "link-to-empty":
            (place / "empty").mkdir()
            target.symlink_to("empty")
        case "file":
            target.write_text("kept")
        case "link-to-file":
            target.symlink_to("kept.txt")
        case "dangling-link":
            target.symlink_to("nowhere")
        case "link-loop":
            target.symlink_to("project")
        case "not-empty":
            target.mkdir()
            (target / "main.rob").write_text("(END)\n")
        case "hidden-file":
            target.mkdir()
            (target / ".keep").write_text("")
        case "fifo":
            os.mkfifo(target)
        case "under-a-file":
            target = place / "kept.txt" / "project"
        case "missing-parent":
            target = place / "missing" / "project"
        case "dash":
            target = Path("-")
    before = _contents(place)
    result = rl1c("new", target)
    found = _problems("new", result, None)
    if kind in ("missing", "empty", "link-to-empty"):
        if result.exit_code != 0:
            found.append(f"new into {kind}: status {result.exit_code}: {result.output[-300:]!r}")
        elif {name: (target / name).read_bytes() for name in PROJECT} != PROJECT:
            found.append(f"new into {kind}: the project is not whole")
    elif result.exit_code != 2:
        found.append(f"new into {kind}: status {result.exit_code}: {result.output[-300:]!r}")
    elif _contents(place) != before:
        found.append(f"new into {kind}: refused, but changed {place}")
    return found


OUTPUT_TARGETS = ["-", "", "folder", "missing/report", "program", "world", "test file",
                  "link to the program", "link loop", "read-only", "the other output",
                  "/dev/null"]
"""Where a hostile command line writes `rl1c test --junit` and a campaign's pictures."""


def _output_target(kind: str, project: Path, other: Path) -> str:
    match kind:
        case "folder":
            return str(project / "folder.rob")
        case "missing/report":
            return str(project / "missing" / "report")
        case "program" | "world" | "test file":
            return str(project / {"program": "main.rob", "world": "main.world.toml",
                                  "test file": "main.tests.toml"}[kind])
        case "link to the program":
            (project / "to-program").unlink(missing_ok=True)
            (project / "to-program").symlink_to("main.rob")
            return str(project / "to-program")
        case "link loop":
            return str(project / "loop.rob")
        case "read-only":
            target = project / "read-only.out"
            if not target.exists():
                target.write_text("kept")
                target.chmod(0o444)
            return str(target)
        case "the other output":
            return str(other)
    return kind


def output_attack(command: str, kind: str, folder: Path) -> list[str]:
    """`rl1c test --junit` (command "test") or `rl1c sim --runs --svg --html` ("svg",
    "html") writing to the target `kind` of OUTPUT_TARGETS: no input changes, a
    read-only file stays as it was without --force, and a command that failed wrote
    nothing new."""
    project = _project(folder)
    other = folder / "other.out"
    target = _output_target(kind, project, other)
    before = _contents(project)
    created = target not in ("-", "/dev/null") and not os.path.lexists(target)
    if command == "test":
        result = rl1c("test", project / "main.tests.toml", "--jobs", "1", "--junit", target)
    else:
        pictures = {"svg": ["--svg", target, "--html", str(other)],
                    "html": ["--html", target, "--out", str(other)]}[command]
        result = rl1c("sim", project / "main.rob", "--world", project / "main.world.toml",
                      "--runs", "2", "--jobs", "1", "--budget", BUDGET, *pictures)
    found = _problems("test" if command == "test" else "sim", result, None)
    refused = {"program", "world", "test file", "read-only", "link to the program",
               *(["the other output"] if command != "test" else [])}
    if result.exit_code == 0 and kind in refused:
        found.append(f"{command} onto {kind}: status 0, where it is refused")
    if _contents(project) != before:
        found.append(f"{command} onto {kind}: changed a file of the project")
    if result.exit_code == 2 and created and os.path.lexists(target):
        found.append(f"{command} onto {kind}: failed but wrote {target}")
    return found
