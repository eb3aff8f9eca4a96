"""`rl1-lsp` over its real standard input and output, byte for byte: what a client
writes is sent as given (broken framing included), and every message the server
writes is read back as parsed JSON."""

from __future__ import annotations

import contextlib
import json
import queue
import subprocess
import threading
from typing import Any

from conftest import SERVER, TIMEOUT

Message = dict[str, Any]


def frame(message: Message | bytes, header: bytes | None = None) -> bytes:
    """A message as a client frames it; `header` replaces the usual one."""
    body = message if isinstance(message, bytes) else json.dumps(message).encode()
    if header is None:
        header = b"Content-Length: %d\r\n\r\n" % len(body)
    return header + body


def request(msg_id: int | str, method: str, params: object = None) -> Message:
    return {"jsonrpc": "2.0", "id": msg_id, "method": method, "params": params}


def notification(method: str, params: object = None) -> Message:
    return {"jsonrpc": "2.0", "method": method, "params": params}


INITIALIZE = request(1, "initialize", {"processId": None, "rootUri": None,
                                       "capabilities": {}})
INITIALIZED = notification("initialized", {})


class RawServer:
    """A running `rl1-lsp`; `messages` receives what it writes, in order."""

    def __init__(self) -> None:
        self.process = subprocess.Popen(SERVER, stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.messages: queue.Queue[Message] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        out = self.process.stdout
        assert out is not None
        while True:
            length = None
            while (line := out.readline()) not in (b"\r\n", b""):
                name, _, value = line.decode().partition(":")
                if name.lower() == "content-length":
                    length = int(value)
            if not line or length is None:
                return
            self.messages.put(json.loads(out.read(length)))

    def send(self, data: bytes) -> None:
        assert self.process.stdin is not None
        self.process.stdin.write(data)
        self.process.stdin.flush()

    def start(self) -> None:
        """Initialize the session."""
        self.send(frame(INITIALIZE))
        assert "capabilities" in self.reply(1)["result"]
        self.send(frame(INITIALIZED))

    def next(self, timeout: float = TIMEOUT) -> Message:
        return self.messages.get(timeout=timeout)

    def reply(self, msg_id: int | str | None) -> Message:
        """The next response with this id, skipping notifications to the client."""
        while True:
            message = self.next()
            if "method" not in message and message.get("id") == msg_id:
                return message

    def error_code(self, msg_id: int | str | None) -> int:
        code: int = self.reply(msg_id)["error"]["code"]
        return code

    def finish(self, timeout: float = TIMEOUT) -> tuple[int, str]:
        """Close its input, and return its exit status and standard error."""
        assert self.process.stdin is not None and self.process.stderr is not None
        with contextlib.suppress(BrokenPipeError):  # it may have exited already
            self.process.stdin.close()
        status = self.process.wait(timeout)
        return status, self.process.stderr.read().decode()

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        for stream in (self.process.stdin, self.process.stdout, self.process.stderr):
            if stream is not None:
                stream.close()
