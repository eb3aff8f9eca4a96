"""`rl1-lsp --tcp` and `--ws` as a client meets them: the real server in a subprocess,
and clients on real sockets that send bytes as given and read back parsed JSON."""

from __future__ import annotations

import contextlib
import json
import socket
import subprocess
import time
from collections.abc import Iterator
from typing import Any

from conftest import SERVER, TIMEOUT
from raw import Message
from support.memory import status_mib


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


class Listening:
    """`rl1-lsp --tcp` or `--ws` on a free local port."""

    def __init__(self, transport: str) -> None:
        self.port = free_port()
        self.process = subprocess.Popen(
            [*SERVER, f"--{transport}", f"127.0.0.1:{self.port}"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        deadline = time.monotonic() + TIMEOUT
        while True:
            assert self.process.poll() is None, self.stderr()
            with contextlib.suppress(OSError), socket.create_connection(
                    ("127.0.0.1", self.port), timeout=1):
                return
            assert time.monotonic() < deadline, "the server did not start listening"
            time.sleep(0.1)

    def resident_mib(self) -> float:
        return status_mib(self.process.pid, "VmRSS")

    def stderr(self) -> str:
        """Standard error so far (ends the server if it still runs)."""
        self.stop()
        assert self.process.stderr is not None
        return self.process.stderr.read().decode()

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(TIMEOUT)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()


@contextlib.contextmanager
def listening(transport: str) -> Iterator[Listening]:
    server = Listening(transport)
    try:
        yield server
    finally:
        server.stop()
        if server.process.stderr is not None:
            server.process.stderr.close()


class TcpClient:
    """One connection to `rl1-lsp --tcp`."""

    def __init__(self, port: int) -> None:
        self.socket = socket.create_connection(("127.0.0.1", port), timeout=TIMEOUT)
        self._buffer = b""

    def send(self, data: bytes) -> None:
        self.socket.sendall(data)

    def next(self) -> Message:
        """The next message the server writes (AssertionError when it closes)."""
        while True:
            head, found, rest = self._buffer.partition(b"\r\n\r\n")
            if found:
                length = int(head.split(b":")[1])
                if len(rest) >= length:
                    self._buffer = rest[length:]
                    message: Message = json.loads(rest[:length])
                    return message
            chunk = self.socket.recv(65536)
            assert chunk, "the server closed the connection"
            self._buffer += chunk

    def reply(self, msg_id: int | str | None) -> Message:
        """The next response with this id, skipping notifications to the client."""
        while True:
            message = self.next()
            if "method" not in message and message.get("id") == msg_id:
                return message

    def published(self) -> dict[str, Any]:
        """The params of the next publishDiagnostics."""
        while (message := self.next()).get("method") != "textDocument/publishDiagnostics":
            pass
        params: dict[str, Any] = message["params"]
        return params

    def closed(self) -> bool:
        """Whether the server has closed the connection (waiting for it at most TIMEOUT)."""
        try:
            while self.socket.recv(65536):
                pass
        except ConnectionResetError:
            pass
        return True

    def close(self) -> None:
        self.socket.close()
