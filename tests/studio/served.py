"""The studio's server as the tests meet it: served in a thread of the test process on a
free port of 127.0.0.1 (`serving`) or as `rl1c studio` in a process of its own
(`StudioProcess`, whose memory is its own), raw HTTP requests sent byte for byte (`get`),
and a page's `/studio` connection driven as JSON-RPC (`Page`)."""

from __future__ import annotations

import asyncio
import contextlib
import json
import re
import shutil
import socket
import subprocess
import sys
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from support import EXAMPLES
from support.memory import status_mib
from websockets.sync.client import ClientConnection, connect
from websockets.typing import Origin

from rl1.lsp.studio.server import STATIC, Gate, Server, new_token, serve_studio
from rl1.lsp.studio.start import studio_for

TIMEOUT = 60


@dataclass(frozen=True)
class Served:
    server: Server

    @property
    def port(self) -> int:
        return self.server.gate.port

    @property
    def token(self) -> str:
        return self.server.gate.token

    def url(self, path: str = "/", token: str | None = None, scheme: str = "http") -> str:
        given = self.token if token is None else token
        return f"{scheme}://127.0.0.1:{self.port}{path}?token={given}"


@contextlib.contextmanager
def serving(folder: Path, program: str | None = None, world: str | None = None,
            static: Path = STATIC) -> Iterator[Served]:
    """The studio for `folder`, served until the block ends."""
    server = Server(Gate(new_token()), studio_for(folder, program, world), static)
    ready = threading.Event()
    running: dict[str, Any] = {}

    async def main() -> None:
        running["loop"] = asyncio.get_running_loop()
        running["task"] = asyncio.current_task()
        await serve_studio(server, 0, lambda port: ready.set())

    def serve() -> None:
        with contextlib.suppress(asyncio.CancelledError):
            asyncio.run(main())

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    assert ready.wait(TIMEOUT), "the studio did not start listening"
    try:
        yield Served(server)
    finally:
        running["loop"].call_soon_threadsafe(running["task"].cancel)
        thread.join(TIMEOUT)


def sample_folder(into: Path) -> Path:
    """A folder holding Listing 1, its world and its sensor script."""
    for name in ("sample.rob", "sample.world.toml", "sample.sensors.json"):
        shutil.copy(EXAMPLES / name, into / name)
    return into


LISTING_1 = {"program": {"path": "sample.rob"}, "world": {"path": "sample.world.toml"}}
"""A launch of Listing 1 on its world, in a `sample_folder`."""


@dataclass(frozen=True)
class Answer:
    status: int
    headers: dict[str, str]
    body: bytes


def get(served: Served, target: str,
        headers: dict[str, str] | list[tuple[str, str]] | None = None,
        method: str = "GET") -> Answer:
    """An HTTP request for `target` exactly as written (no normalizing of `..`); headers
    as a list may repeat a name, and a Host among them replaces the server's."""
    given = list(headers.items()) if isinstance(headers, dict) else list(headers or [])
    own_host = [] if any(name == "Host" for name, _ in given) else [
        ("Host", f"127.0.0.1:{served.port}")]
    request = f"{method} {target} HTTP/1.1\r\n" + "".join(
        f"{name}: {value}\r\n" for name, value in own_host + given) + "\r\n"
    with socket.create_connection(("127.0.0.1", served.port), timeout=TIMEOUT) as client:
        client.sendall(request.encode())
        received = b""
        while chunk := client.recv(65536):
            received += chunk
    head, _, body = received.partition(b"\r\n\r\n")
    status_line, *lines = head.decode("latin-1").split("\r\n")
    fields = dict(line.split(": ", 1) for line in lines)
    return Answer(int(status_line.split()[1]), fields, body)


class Failed(Exception):
    """A JSON-RPC error answering a request."""

    def __init__(self, error: dict[str, Any]) -> None:
        super().__init__(error["message"])
        self.code: int = error["code"]
        self.data: Any = error.get("data")


class Page:
    """A page's `/studio` connection: requests numbered from 1; the notifications that
    come meanwhile kept in order."""

    def __init__(self, connection: ClientConnection) -> None:
        self.connection = connection
        self.notifications: list[dict[str, Any]] = []
        self.skipped: list[dict[str, Any]] = []  # passed over by `until`
        self._id = 0

    def send(self, message: object) -> None:
        self.connection.send(message if isinstance(message, str) else json.dumps(message))

    def answer(self, msg_id: object) -> dict[str, Any]:
        while True:
            message = json.loads(self.connection.recv(timeout=TIMEOUT))
            if "method" in message:
                self.notifications.append(message)
            elif message.get("id") == msg_id:
                answer: dict[str, Any] = message
                return answer

    def request(self, method: str, params: dict[str, Any] | None = None) -> Any:
        """The result; Failed with the error."""
        self._id += 1
        self.send({"jsonrpc": "2.0", "id": self._id, "method": method,
                   "params": params or {}})
        answer = self.answer(self._id)
        if "error" in answer:
            raise Failed(answer["error"])
        return answer["result"]

    def until(self, *methods: str) -> dict[str, Any]:
        """The params of the next notification of one of `methods` (those before it
        kept)."""
        while True:
            if self.notifications:
                message = self.notifications.pop(0)
            else:
                message = json.loads(self.connection.recv(timeout=TIMEOUT))
                if "method" not in message:
                    raise AssertionError(f"an answer nobody waited for: {message}")
            if message["method"] in methods:
                params: dict[str, Any] = message["params"]
                params["method"] = message["method"]
                return params
            self.skipped.append(message)


@contextlib.contextmanager
def page(served: Served, origin: str | None = None) -> Iterator[Page]:
    with connect(served.url("/studio", scheme="ws"), max_size=None, open_timeout=TIMEOUT,
                 origin=None if origin is None else Origin(origin)) as connection:
        yield Page(connection)


RL1C = [sys.executable, "-c", "from rl1.compiler.cli.main import rl1c; rl1c()"]
ADDRESS = re.compile(r"^rl1c studio: serving (?P<folder>.+) at "
                     r"(?P<url>http://127\.0\.0\.1:(?P<port>\d+)/\?token=(?P<token>[\w-]+)) "
                     r"\(Ctrl-C stops it\)$")
"""The line `rl1c studio` prints first."""


class StudioProcess:
    """`rl1c studio --no-browser` serving `folder`, in a process of its own."""

    def __init__(self, folder: Path) -> None:
        self.process = subprocess.Popen([*RL1C, "studio", "--no-browser"], cwd=folder,
                                        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                        text=True)
        assert self.process.stdout is not None
        shown = ADDRESS.match(self.process.stdout.readline().rstrip("\n"))
        if shown is None:
            self.stop()
            raise AssertionError("rl1c studio did not print its address")
        self.port, self.token = int(shown["port"]), shown["token"]

    def url(self, path: str) -> str:
        return f"ws://127.0.0.1:{self.port}{path}?token={self.token}"

    def resident_mib(self) -> float:
        return status_mib(self.process.pid, "VmRSS")

    def peak_mib(self) -> float:
        """The most resident memory the process has held."""
        return status_mib(self.process.pid, "VmHWM")

    def stop(self) -> None:
        self.process.kill()
        self.process.wait(TIMEOUT)


def pages_one_after_another(studio: StudioProcess, pages: int) -> None:
    """`pages` pages, each leaving before the next comes, as a user's: each launches
    Listing 1 on its world, stops on entry, steps a line and sets a breakpoint, and is
    closed stopped (its run held, not ended). The folder is a `sample_folder`."""
    for _ in range(pages):
        with connect(studio.url("/studio"), max_size=None, open_timeout=TIMEOUT) as socket_:
            client = Page(socket_)
            client.request("initialize")
            client.request("run/launch", {**LISTING_1, "stopOnEntry": True})
            client.until("run/stopped")
            client.request("debug/setBreakpoints", {"lines": [{"line": 3}]})
            client.request("debug/stepLine")
            client.until("run/stopped", "run/ended")
