"""How `rl1-lsp` meets its clients: standard input and output, TCP, or a WebSocket.

Whatever the transport, a connection is one session (a `Session`: its own documents, its
own `initialize` and `exit`), and every message reaches it through the same bounded
reading: framing.py's reader on a byte stream, the WebSocket library's own message
limit (framing.MAX_MESSAGE too) on a WebSocket. pygls' `start_tcp` and `start_ws` give
every connection one shared session, so that a second client takes over the first's
documents and diagnostics, read without bounds, and end the process when the first
client leaves; they are not used. What would let them be: a session per connection
(openlawlibrary/pygls#219, open since 2021) and a bounded reader (no upstream issue as
of pygls 2.1.1). This module needs only pygls' public `JsonRPCProtocol.set_writer`
(with `include_headers=False`: the writers here frame each message themselves, in bytes
where pygls counts characters, openlawlibrary/pygls#604).

TCP and WebSocket serve up to MAX_SESSIONS clients at once, each a session of its own,
rather than one client at a time: the studio opens a WebSocket per page, and an editor
that reconnects must not find its old connection holding the server. A client beyond
the limit is told so (an error answering its first request on TCP, close code 1013 on a
WebSocket). What the server holds is bounded per session (its open documents,
server.MAX_OPEN_CHARACTERS; one message being read; MAX_UNREAD bytes written that the
client has not read), so by MAX_SESSIONS times that in all. A connection that has not
sent `initialize` within INITIALIZE_SECONDS is closed, so that a local process cannot
hold every place by connecting and saying nothing.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import os
import re
import threading
from collections.abc import AsyncIterator, Callable
from concurrent.futures import CancelledError
from typing import Any, BinaryIO, Protocol

from .framing import CHUNK, MAX_MESSAGE, Framer, frame

log = logging.getLogger(__name__)

MAX_SESSIONS = 8
"""Clients served at once over TCP or WebSocket."""
MAX_UNREAD = 2 * MAX_MESSAGE
"""Bytes written to a client that it has not read yet: past this, it is disconnected."""
REFUSAL_SECONDS = 10.0
"""How long a client beyond MAX_SESSIONS has to send the request that is refused."""
INITIALIZE_SECONDS = 10.0
"""How long a connection has to send `initialize`: past this, it is closed, so that
connections that send nothing cannot hold every place."""
REQUEST_FAILED = -32803  # LSP's code for a valid request that failed

LOCAL_ORIGIN = re.compile(r"https?://(localhost|127\.0\.0\.1|\[::1\])(:\d+)?")
"""The WebSocket clients accepted: programs (which send no Origin) and pages served from
this machine (this Origin). Any other web page the user visits could otherwise talk to the server
(Cross-Site WebSocket Hijacking) and have it read the rl1.toml files it names."""

BUSY = (f"rl1-lsp is serving {MAX_SESSIONS} clients, as many as it serves at once: "
        "close one of them, or start another rl1-lsp on another port")


class Writer(Protocol):
    """What pygls writes each message's body to (unframed: the writer frames it)."""

    def write(self, data: bytes) -> None: ...

    def close(self) -> None: ...


class Session(Protocol):
    """One client's session of LSP (server.Rl1Server)."""

    @property
    def exit_status(self) -> int | None:
        """None until the client sends `exit`; then the status LSP gives it."""

    @property
    def initialized(self) -> bool:
        """Whether the client has sent `initialize`."""

    def attach(self, writer: Writer) -> None:
        """Write every message to `writer`."""

    def receive(self, body: bytes) -> None:
        """Handle one message's body."""

    def end(self) -> None:
        """The connection is over: stop whatever the session still runs."""


async def _serve_stream(session: Session, chunks: AsyncIterator[bytes]) -> None:
    """Hand `session` each message read from a byte stream, until its end or `exit`."""
    framer = Framer()
    async for chunk in chunks:
        for body in framer.feed(chunk):
            session.receive(body)
            if session.exit_status is not None:
                return
        for problem in framer.problems:
            log.warning("skipped %s; reading on from the next Content-Length header. "
                        "The client is breaking LSP's framing: please report it", problem)
        framer.problems.clear()


async def _close_unless_initialized(session: Session, close: Callable[[], object]) -> None:
    """Call `close` if `session` has not received `initialize` in INITIALIZE_SECONDS."""
    await asyncio.sleep(INITIALIZE_SECONDS)
    if not session.initialized:
        log.warning("a client sent no initialize in %.0f s: disconnected", INITIALIZE_SECONDS)
        close()


@contextlib.asynccontextmanager
async def _initialize_deadline(session: Session, close: Callable[[], object]
                               ) -> AsyncIterator[None]:
    """While inside, `close` is called if `session` is not initialized in time."""
    watch = asyncio.create_task(_close_unless_initialized(session, close))
    try:
        yield
    finally:
        watch.cancel()


# Standard input and output ----------------------------------------------------------------

class _OutputWriter:
    def __init__(self, output: BinaryIO) -> None:
        self._output = output
        self._lost = False

    def write(self, data: bytes) -> None:
        if self._lost:
            return
        try:
            self._output.write(frame(data))
            self._output.flush()
        except OSError as error:  # the client has gone: its input ends too
            log.error("cannot write to the client (%s): it has closed its end", error)
            self._lost = True

    def close(self) -> None:
        """Standard output stays open: the process ends soon after."""


async def _read_fd(fd: int) -> AsyncIterator[bytes]:
    loop = asyncio.get_running_loop()
    chunks: asyncio.Queue[bytes] = asyncio.Queue(maxsize=4)

    def read() -> None:
        # A daemon thread with os.read: a blocked read neither holds a lock nor delays
        # the exit that LSP's `exit` asks for.
        while True:
            try:
                chunk = os.read(fd, CHUNK)
            except OSError as error:
                log.error("cannot read from the client (%s)", error)
                chunk = b""
            put = chunks.put(chunk)
            try:
                asyncio.run_coroutine_threadsafe(put, loop).result()
            except (RuntimeError, CancelledError):  # the loop has ended: the server exits
                put.close()
                return
            if not chunk:
                return

    threading.Thread(target=read, name="rl1-lsp stdin", daemon=True).start()
    while chunk := await chunks.get():
        yield chunk


def serve_stdio(session: Session, stdin: BinaryIO, stdout: BinaryIO) -> int:
    """Serve one session over standard input and output; returns the exit status: the
    one LSP's `exit` gives, or 0 when the input ends."""
    async def serve() -> None:
        session.attach(_OutputWriter(stdout))
        try:
            await _serve_stream(session, _read_fd(stdin.fileno()))
        finally:
            session.end()

    asyncio.run(serve())
    return session.exit_status or 0


# TCP ------------------------------------------------------------------------------------

class _TcpWriter:
    def __init__(self, stream: asyncio.StreamWriter) -> None:
        self._stream = stream

    def write(self, data: bytes) -> None:
        if self._stream.is_closing():
            return
        self._stream.write(frame(data))
        if self._stream.transport.get_write_buffer_size() > MAX_UNREAD:
            log.warning("a client has not read %s MiB the server wrote: disconnected",
                        MAX_UNREAD // 2**20)
            self._stream.transport.abort()

    def close(self) -> None:
        self._stream.close()


async def _read_tcp(reader: asyncio.StreamReader, writer: asyncio.StreamWriter
                    ) -> AsyncIterator[bytes]:
    while chunk := await reader.read(CHUNK):
        yield chunk
        await writer.drain()  # a client that does not read is not read either


def _request_id(body: bytes) -> object:
    """The id of the request in `body`, or None."""
    try:
        data = json.loads(body)
    except (ValueError, RecursionError):
        return None
    return data.get("id") if isinstance(data, dict) and "method" in data else None


async def _refuse_tcp(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
    """Answer the first request of a client beyond MAX_SESSIONS with BUSY, and close."""
    framer = Framer(limit=CHUNK)  # an initialize is a few KB
    with contextlib.suppress(TimeoutError):
        async with asyncio.timeout(REFUSAL_SECONDS):
            async for chunk in _read_tcp(reader, writer):
                for body in framer.feed(chunk):
                    if (msg_id := _request_id(body)) is not None:
                        answer = {"jsonrpc": "2.0", "id": msg_id,
                                  "error": {"code": REQUEST_FAILED, "message": BUSY}}
                        writer.write(frame(json.dumps(answer).encode()))
                        await writer.drain()
                        return


async def serve_tcp(new_session: Callable[[], Session], host: str, port: int) -> None:
    """Serve each connection to HOST:PORT as a session of its own, until stopped."""
    sessions: set[Session] = set()
    refusing: set[asyncio.StreamWriter] = set()  # bounded too: beyond, closed at once

    async def connected(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        try:
            if len(sessions) >= MAX_SESSIONS:
                log.warning("a client beyond the %d served at once: refused", MAX_SESSIONS)
                if len(refusing) < MAX_SESSIONS:
                    refusing.add(writer)
                    try:
                        await _refuse_tcp(reader, writer)
                    finally:
                        refusing.discard(writer)
                return
            session = new_session()
            sessions.add(session)
            session.attach(_TcpWriter(writer))
            try:
                async with _initialize_deadline(session, writer.transport.abort):
                    await _serve_stream(session, _read_tcp(reader, writer))
            finally:
                sessions.discard(session)
                session.end()
        except OSError as error:  # the client went away mid-way
            log.info("a connection ended: %s", error)
        finally:
            writer.close()

    server = await asyncio.start_server(connected, host, port)
    log.info("serving LSP on %s", ", ".join(str(s.getsockname()) for s in server.sockets))
    async with server:
        await server.serve_forever()


# WebSocket ------------------------------------------------------------------------------

class _WebSocketWriter:
    """Sends each message as a text frame, in order, from a task of its own."""

    def __init__(self, connection: Any) -> None:
        self._connection = connection
        self._outbox: asyncio.Queue[str] = asyncio.Queue()
        self._unsent = 0
        self._pump = asyncio.get_running_loop().create_task(self._send_all())

    def write(self, data: bytes) -> None:
        self._unsent += len(data)
        if self._unsent > MAX_UNREAD:
            log.warning("a client has not read %s MiB the server wrote: disconnected",
                        MAX_UNREAD // 2**20)
            self._connection.transport.abort()
            return
        self._outbox.put_nowait(data.decode())

    async def _send_all(self) -> None:
        from websockets.exceptions import ConnectionClosed
        with contextlib.suppress(ConnectionClosed):
            while True:
                text = await self._outbox.get()
                await self._connection.send(text)
                self._unsent -= len(text)  # JSON as pygls writes it is ASCII
                self._outbox.task_done()

    async def finish(self) -> None:
        """Send what is still waiting (for a while), then stop."""
        with contextlib.suppress(TimeoutError):
            async with asyncio.timeout(REFUSAL_SECONDS):
                await self._outbox.join()
        self.close()

    def close(self) -> None:
        self._pump.cancel()


class _OneLine(logging.Filter):
    """Says an exception in one line, not as a traceback: the websockets library logs one
    as an "unexpected internal error" when a client half-closes its socket while the
    server answers its opening handshake (websockets 17.4, send_eof's assertion); the
    server goes on serving."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.exc_info is not None and record.exc_info[1] is not None:
            error = record.exc_info[1]
            record.msg = f"{record.msg} ({type(error).__name__}: {error}); a client's " \
                "connection ended, the server goes on"
            record.exc_info = None
        return True


WEBSOCKETS_LOG = logging.getLogger(f"{__name__}.websockets")
"""The websockets library's logger for the WebSocket servers here and the studio's."""
WEBSOCKETS_LOG.addFilter(_OneLine())


class WebSocketSessions:
    """The LSP sessions of one server's WebSocket connections, a session a connection,
    at most MAX_SESSIONS. `rl1-lsp --ws` and the studio's `/lsp` (lsp/studio/) serve a
    connection with `serve`; their server makes its connections of `connection_class`."""

    def __init__(self) -> None:
        from websockets.asyncio.server import ServerConnection

        self.sessions: set[Session] = set()
        self.connection_class = ServerConnection

    async def serve(self, connection: Any, new_session: Callable[[], Session]) -> None:
        """Serve `connection` (of `connection_class`) as a session of its own, one LSP
        message a WebSocket message, until it closes or the session exits."""
        from websockets.exceptions import ConnectionClosed

        sessions = self.sessions
        if len(sessions) >= MAX_SESSIONS:
            log.warning("a client beyond the %d served at once: refused", MAX_SESSIONS)
            await connection.close(1013, BUSY[:123])  # 1013: try again later
            return
        session = new_session()
        sessions.add(session)
        writer = _WebSocketWriter(connection)
        session.attach(writer)
        try:
            async with _initialize_deadline(session, connection.transport.abort):
                async for message in connection:
                    session.receive(message.encode() if isinstance(message, str) else message)
                    if session.exit_status is not None:
                        break
        except ConnectionClosed as closed:  # such as a message over MAX_MESSAGE
            log.info("a WebSocket connection ended: %s", closed)
        finally:
            sessions.discard(session)
            session.end()
            await writer.finish()


async def serve_websocket(new_session: Callable[[], Session], host: str, port: int) -> None:
    """Serve each WebSocket connection to HOST:PORT as a session of its own, one LSP
    message a WebSocket message, until stopped. Needs the `websockets` package."""
    from websockets.asyncio.server import ServerConnection, serve

    lsp = WebSocketSessions()

    async def connected(connection: ServerConnection) -> None:
        await lsp.serve(connection, new_session)

    async with serve(connected, host, port, create_connection=lsp.connection_class,
                     max_size=MAX_MESSAGE, max_queue=1,
                     origins=[None, LOCAL_ORIGIN], logger=WEBSOCKETS_LOG) as server:
        log.info("serving LSP over WebSocket on %s",
                 ", ".join(str(s.getsockname()) for s in server.sockets))
        await server.serve_forever()
