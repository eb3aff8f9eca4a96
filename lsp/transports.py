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
WebSocket). What the server holds for its clients is bounded: each session's open
documents (server.MAX_OPEN_CHARACTERS), and the bytes in flight of all sessions together
(InFlight: messages being read, answers their clients have not read yet), so that eight
clients sending a message of framing.MAX_MESSAGE each at once do not hold eight, and the
first of them to need more than its free share is read whatever the others send. A
connection that has not
sent `initialize` within INITIALIZE_SECONDS is closed, so that a local process cannot
hold every place by connecting and saying nothing.

On a WebSocket, messages are text, as RFC 6455 has a server refuse what it cannot
accept: a binary message fails its connection with close code 1003, text not in UTF-8
with 1007, and an HTTP request the library cannot read is answered 400 (it answers a
line too long with 414 or 431 itself), where it closed the connection without a word.
"""

from __future__ import annotations

import asyncio
import contextlib
import ctypes
import functools
import gc
import json
import logging
import os
import re
import threading
from collections.abc import AsyncIterator, Callable, Iterator
from concurrent.futures import CancelledError
from typing import Any, BinaryIO, Protocol

from rl1.compiler.frontend.collector import FullCollections
from rl1.vm.config import excerpt

from .framing import CHUNK, MAX_MESSAGE, Admission, Framer, frame
from .json_reading import read_json

log = logging.getLogger(__name__)

MAX_SESSIONS = 8
"""Clients served at once over TCP or WebSocket."""
FREE_IN_FLIGHT = 2**20
"""Bytes in flight a session may always hold, whatever the others hold (an editor's
messages and the answers to them are far smaller), so that no client starves another."""
MAX_IN_FLIGHT = 2 * MAX_MESSAGE
"""Bytes in flight that a server's sessions may hold between them beyond FREE_IN_FLIGHT
each (RESERVED_IN_FLIGHT of it kept for one session's message): a message that would
pass it is skipped (TCP; the client is told) or its connection closed (WebSocket, close
code 1009), and a client that would pass it by not reading is disconnected."""
RESERVED_IN_FLIGHT = MAX_MESSAGE
"""Of MAX_IN_FLIGHT, the bytes kept for the first session to need more than its free
share (InFlight), so that of several large messages read at once one is always read."""
MEMORY_IN_FLIGHT = MAX_IN_FLIGHT + MAX_SESSIONS * FREE_IN_FLIGHT + 2 * MAX_MESSAGE
"""The most memory a server's messages in flight take, 264 MiB: each byte in flight once,
and the message being decoded (one at a time: sessions share one thread) twice more, as
the text JSON decodes it to and the strings it holds. Measured by
tests/lsp/test_hostile_transports.py (eight clients each sending MAX_MESSAGE bytes)."""
REFUSAL_SECONDS = 10.0
"""How long a client beyond MAX_SESSIONS has to send the request that is refused."""
INITIALIZE_SECONDS = 10.0
"""How long a connection has to send `initialize` (a studio page, its first message):
past this, it is closed, so that connections that send nothing cannot hold every place."""
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


class InFlight:
    """The bytes in flight of a server's sessions (each message being read, the answers
    written that its client has not read), each session counting its own when asked, so
    that there is nothing to give back when a message is done or a session ends.

    Beyond FREE_IN_FLIGHT each, the sessions share MAX_IN_FLIGHT, and the first session
    to need more than its free share holds a reservation of RESERVED_IN_FLIGHT, which
    counts against the others whether or not it has read that much yet, until it holds
    no more than its free share again. Without it, which of several large messages read
    at once fitted depended on how their bytes interleaved: eight clients sending 60 MiB
    each over WebSocket all grew together, and each was refused midway, none read. With
    it, the holder's message (up to RESERVED_IN_FLIGHT beyond its free share) is always
    read to its end, and the others share what is left."""

    def __init__(self) -> None:
        self._held: dict[object, Callable[[], int]] = {}
        self._reserved: object | None = None  # the session holding the reservation

    @contextlib.contextmanager
    def counting(self, session: object, held: Callable[[], int]) -> Iterator[None]:
        """While inside, `held()` says how many bytes `session` holds."""
        self._held[session] = held
        try:
            yield
        finally:
            del self._held[session]
            if self._reserved is session:
                self._reserved = None

    def __contains__(self, session: object) -> bool:
        return session in self._held

    def refusal(self, session: object, more: int = 0) -> str | None:
        """None if `session` may hold `more` bytes beyond what it holds, else why not."""
        mine = self._beyond_free(session) + more
        if mine <= 0:
            return None
        if self._reserved is not None and self._beyond_free(self._reserved) <= 0:
            self._reserved = None  # its message is done: the next to need more takes it
        if self._reserved is None:
            self._reserved = session
        others = sum(self._counted(other, self._beyond_free(other))
                     for other in self._held if other is not session)
        if others + self._counted(session, mine) <= MAX_IN_FLIGHT:
            return None
        return (f"the server holds {others / 2**20:.0f} MiB for other clients' messages "
                f"and answers, and {MAX_IN_FLIGHT // 2**20} MiB at most between them; "
                "send it again when they are done")

    def _beyond_free(self, session: object) -> int:
        return self._held[session]() - FREE_IN_FLIGHT

    def _counted(self, session: object, beyond_free: int) -> int:
        """What `session`, holding `beyond_free` bytes beyond its free share, takes of
        MAX_IN_FLIGHT: at least the reservation if it holds it."""
        if session is self._reserved:
            return max(beyond_free, RESERVED_IN_FLIGHT)
        return max(0, beyond_free)


def _show_error(text: str) -> bytes:
    """LSP's window/showMessage of an error, which a server may send at any time."""
    return json.dumps({"jsonrpc": "2.0", "method": "window/showMessage",
                       "params": {"type": 1, "message": f"rl1-lsp: {text}"}}).encode()


async def _serve_stream(session: Session, chunks: AsyncIterator[bytes], framer: Framer,
                        tell: Writer | None = None) -> None:
    """Hand `session` each message read from a byte stream by `framer`, until its end or
    `exit`; what it skips is logged, and told to the client through `tell`."""
    async for chunk in chunks:
        if not _receive(session, framer, chunk, tell):
            return


def _receive(session: Session, framer: Framer, chunk: bytes, tell: Writer | None) -> bool:
    """Hand `session` the messages that `chunk` completes; False once it has exited. A
    function of its own, so that no message outlives it: the variables of a coroutine
    live until it ends, and eight sessions each keeping their last message of
    MAX_MESSAGE bytes grew the server by 577 MiB."""
    for body in framer.feed(chunk):
        session.receive(body)
        if session.exit_status is not None:
            return False
    for problem in framer.problems:
        log.warning("skipped %s; reading on from the next Content-Length header. "
                    "The client is breaking LSP's framing: please report it", problem)
        if tell is not None:
            tell.write(_show_error(f"skipped {problem}"))
    framer.problems.clear()
    return True


async def _close_unless(opened: Callable[[], bool], close: Callable[[], object],
                        silent: str) -> None:
    """Call `close` if `opened()` is still false INITIALIZE_SECONDS from now."""
    await asyncio.sleep(INITIALIZE_SECONDS)
    if not opened():
        log.warning("%s in %.0f s: disconnected", silent, INITIALIZE_SECONDS)
        close()


@contextlib.asynccontextmanager
async def opening_deadline(opened: Callable[[], bool], close: Callable[[], object],
                           silent: str) -> AsyncIterator[None]:
    """While inside, `close` is called if `opened()` (a session's `initialized`, a studio
    page's first message) is not true within INITIALIZE_SECONDS; `silent` says in the
    log what did not come ("a client sent no initialize")."""
    watch = asyncio.create_task(_close_unless(opened, close, silent))
    try:
        yield
    finally:
        watch.cancel()


def _initialize_deadline(session: Session, close: Callable[[], object]
                         ) -> contextlib.AbstractAsyncContextManager[None]:
    """While inside, `close` is called if `session` is not initialized in time."""
    return opening_deadline(lambda: session.initialized, close,
                            "a client sent no initialize")


M_MMAP_THRESHOLD = -3  # mallopt's parameter, from glibc's malloc.h
MMAP_THRESHOLD = 128 * 2**10  # glibc's own default


def return_large_buffers() -> None:
    """Have the C allocator give each large buffer (a message, a WebSocket frame) back
    to the system when it is freed. glibc maps a buffer of 128 KiB or more on its own,
    and unmaps it when freed, but after the first such free it raises that threshold
    up to 32 MiB, and buffers below it come from its heap, which it seldom shrinks: a
    server that had read large messages kept their room for good, 321 MiB free in its
    heap after twelve clients had each sent 64 MiB in fragments (issue 23). Setting
    the threshold, even to its default, stops the raising. Elsewhere than glibc,
    nothing to do."""
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None).mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)


class Collector(FullCollections):
    """Collects the garbage of ended sessions (and the studio's ended pages): `count`
    each as it ends. What a session leaves after its end (server.Rl1Server.end lets go
    of its documents) is a web of reference cycles, pygls' server and protocol and the
    handlers that close over the server, freed only by a collection of the oldest
    generation, where the front end's pauses of the collector move every object
    (compiler/frontend/collector.py). So ended sessions were never freed, and after
    about 1,000 clients the hostile harness's bound was passed (issue 23). A collection
    walks every object of the server, a few times what starting a session costs
    (bench/lsp_sessions.py): hence one for several sessions, at most MAX_SESSIONS of
    them left to it."""

    def __init__(self) -> None:
        super().__init__(MAX_SESSIONS)

    def collect(self) -> None:
        """Once the task serving the session that ended has let go of it."""
        asyncio.get_running_loop().call_soon(gc.collect)


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
            await _serve_stream(session, _read_fd(stdin.fileno()), Framer())
        finally:
            session.end()

    asyncio.run(serve())
    return session.exit_status or 0


# TCP ------------------------------------------------------------------------------------

class _TcpWriter:
    def __init__(self, stream: asyncio.StreamWriter, refusal: Admission) -> None:
        self._stream = stream
        self._refusal = refusal  # why the session may not hold so many bytes more, if so

    @property
    def unread(self) -> int:
        """Bytes written that the client has not read yet."""
        return self._stream.transport.get_write_buffer_size()

    def write(self, data: bytes) -> None:
        if self._stream.is_closing():
            return
        framed = frame(data)
        if (refused := self._refusal(len(framed))) is not None:
            log.warning("a client has not read %.0f MiB the server wrote, and %s: "
                        "disconnected", self.unread / 2**20, refused)
            self._stream.transport.abort()
            return
        self._stream.write(framed)

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
        data = read_json(body)
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
    return_large_buffers()
    sessions: set[Session] = set()
    refusing: set[asyncio.StreamWriter] = set()  # bounded too: beyond, closed at once
    in_flight = InFlight()
    collector = Collector()

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
            admit: Admission = functools.partial(in_flight.refusal, session)
            framer = Framer(admit=admit)
            tcp_writer = _TcpWriter(writer, admit)
            session.attach(tcp_writer)
            try:
                with in_flight.counting(session, lambda: framer.reading + tcp_writer.unread):
                    async with _initialize_deadline(session, writer.transport.abort):
                        await _serve_stream(session, _read_tcp(reader, writer), framer,
                                            tcp_writer)
            finally:
                sessions.discard(session)
                session.end()
                collector.count()
                # The frames of a connection reset live on, in a reference cycle through
                # the exception, until the garbage collector runs (it rarely does, as
                # a buffer of 64 MiB counts as one object): let go of the message now.
                framer.discard()
        except OSError as error:  # the client went away mid-way
            log.info("a connection ended: %s", error)
        finally:
            writer.close()

    server = await asyncio.start_server(connected, host, port)
    log.info("serving LSP on %s", ", ".join(str(s.getsockname()) for s in server.sockets))
    async with server:
        await server.serve_forever()


# WebSocket ------------------------------------------------------------------------------

def fail_websocket(connection: Any, code: int, reason: str) -> None:
    """Close a WebSocket `connection` (websockets' asyncio ServerConnection) at once with
    close `code` and `reason` (cut to the 123 bytes a close frame holds): failed, not
    closed, because while close() waits for the client's answer the library reads its
    messages, up to max_size a frame, counted nowhere."""
    connection.protocol.fail(code, reason[:123])
    connection.send_data()
    connection.transport.close()


async def read_text(connection: Any) -> bytes:
    """The next message of `connection` (of WebSocketSessions' `connection_class`, which
    refuses a binary one), a text message's bytes: checked to be UTF-8, not decoded (the
    JSON reader decodes them; one copy fewer is 64 MiB less at the peak). One that is
    not UTF-8 fails the connection with code 1007 (RFC 6455 8.1), which the library does
    only when it decodes. ConnectionClosed once the connection has ended or failed."""
    from websockets.frames import CloseCode

    body: bytes = await connection.recv(decode=False)
    if body.isascii():  # JSON as editors and the page write it: no copy to check it
        return body
    try:
        body.decode()  # checked only: the decoded text is let go at once
    except UnicodeDecodeError as error:
        where = f"{error.reason} at byte {error.start}"
        log.warning("closed a WebSocket connection (1007): a text message not in UTF-8 "
                    "(%s)", where)
        fail_websocket(connection, CloseCode.INVALID_DATA,
                       f"a text message not in UTF-8 ({where}): send text in UTF-8")
        await connection.wait_closed()
        raise connection.close_exc from None
    return body


def _hand_over(session: Session, body: bytes) -> int:
    """Hand `session` a WebSocket message's bytes; returns the bytes it leaves in flight:
    the websockets library keeps the last frame it read (in a variable of its parser)
    until it has read the next."""
    session.receive(body)
    return len(body)


def _unreadable(cause: BaseException | None) -> str:
    """What is wrong with an HTTP request that the websockets library could not read
    (`cause`, its parser's error), and what to do."""
    if isinstance(cause, UnicodeDecodeError):  # its text says only "'ascii' codec..."
        return "the request line is not ASCII: percent-encode its path (RFC 3986)"
    return f"{excerpt(str(cause))}: send an HTTP/1.1 GET without a body"


class WebSocketOutbox:
    """Sends each message as a text frame, in order, from a task of its own; a peer that
    would leave more unread than the bound of the bytes in flight allows (`refusal`:
    InFlight's) is disconnected. An rl1-lsp session writes through it (a Writer), and
    so does a studio page (studio/server.py), `peer` in the log."""

    def __init__(self, connection: Any, refusal: Admission, peer: str = "a client") -> None:
        self._connection = connection
        self._refusal = refusal  # why the session may not hold so many bytes more, if so
        self._peer = peer
        self._outbox: asyncio.Queue[str] = asyncio.Queue()
        self.unsent = 0
        self._closed = False
        self._pump = asyncio.get_running_loop().create_task(self._send_all())

    def write(self, data: bytes) -> None:
        self.send(data.decode())

    def send(self, text: str) -> None:
        if self._closed:  # the peer has gone, and is counted no more
            return
        # JSON as pygls and json.dumps write it is ASCII: its length is its bytes'.
        if (refused := self._refusal(len(text))) is not None:
            log.warning("%s has not read %.0f MiB the server wrote, and %s: disconnected",
                        self._peer, self.unsent / 2**20, refused)
            self._connection.transport.abort()
            return
        self.unsent += len(text)
        self._outbox.put_nowait(text)

    async def _send_all(self) -> None:
        from websockets.exceptions import ConnectionClosed
        with contextlib.suppress(ConnectionClosed):
            while True:
                text = await self._outbox.get()
                await self._connection.send(text)
                self.unsent -= len(text)
                self._outbox.task_done()

    async def finish(self) -> None:
        """Send what is still waiting (for a while), then stop."""
        with contextlib.suppress(TimeoutError):
            async with asyncio.timeout(REFUSAL_SECONDS):
                await self._outbox.join()
        self.close()

    def close(self) -> None:
        self._closed = True
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
    """The LSP sessions of one server's WebSocket connections, a session a connection:
    at most MAX_SESSIONS, their bytes in flight bounded together (InFlight). `rl1-lsp
    --ws` and the studio's `/lsp` (lsp/studio/) serve a connection with `serve`; their
    server makes its connections of `connection_class`, which counts what they receive
    (only those served here)."""

    def __init__(self) -> None:
        from http import HTTPStatus

        from websockets.asyncio.server import ServerConnection
        from websockets.exceptions import InvalidMessage
        from websockets.frames import DATA_OPCODES, CloseCode, Frame, Opcode
        from websockets.protocol import State

        return_large_buffers()
        self.sessions: set[Session] = set()
        in_flight = self.in_flight = InFlight()
        self.collector = Collector()  # the studio's pages' too

        class Counted(ServerConnection):
            """A connection that counts the bytes received since its last message was
            handled, and is closed when they would pass what InFlight allows: the library
            reads a whole message before handing it over. It reads nothing while its
            client has not read what was written to it (the library's answers to pings
            too, which nothing else bounds). It takes text messages only, and answers a
            request it cannot read as HTTP."""

            received = 0
            answered_unreadable = False

            def process_event(self, event: Any) -> None:
                if isinstance(event, Frame) and event.opcode in DATA_OPCODES:
                    if self.protocol.state is not State.OPEN:
                        return  # failed: nothing more is processed (RFC 6455 7.1.7)
                    if event.opcode is Opcode.BINARY:
                        # RFC 6455 7.4.1: data of a type the server cannot accept. Refused
                        # at its first frame, before the message is read.
                        log.warning("closed a WebSocket connection (1003): it sent a binary "
                                    "message, where JSON-RPC comes in text messages")
                        fail_websocket(self, CloseCode.UNSUPPORTED_DATA, "binary messages "
                                       "are not read: send each message as a text message")
                        return
                super().process_event(event)

            def send_data(self) -> None:
                # The library answers a request it cannot read only when a line is too
                # long (414, 431); any other (a body, a request line not in ASCII, a line
                # it cannot split) it closes without a word: it is answered 400 here,
                # before the end of the stream the library writes. A client that closed
                # before its request's end is not answered.
                failed = self.protocol.handshake_exc
                if (isinstance(failed, InvalidMessage) and not self.answered_unreadable
                        and not isinstance(failed.__cause__, EOFError)):
                    self.answered_unreadable = True
                    what = _unreadable(failed.__cause__)
                    log.warning("answered 400 Bad Request to an HTTP request it cannot "
                                "read: %s", what)
                    self.transport.write(self.protocol.reject(
                        HTTPStatus.BAD_REQUEST, f"Bad request: {what}.\n").serialize())
                super().send_data()

            def data_received(self, data: bytes) -> None:
                self._count_and_receive(data)
                # The library answers a ping as it reads it, whatever is still unread:
                # from a client that never reads, nothing more is read until it does.
                if self.paused:
                    self.transport.pause_reading()

            def resume_writing(self) -> None:
                super().resume_writing()
                if not self.recv_messages.paused:  # the library's own pause stands
                    self.transport.resume_reading()

            def _count_and_receive(self, data: bytes) -> None:
                if self.protocol.state is not State.OPEN or self not in in_flight:
                    super().data_received(data)
                    return
                if (refused := in_flight.refusal(self, len(data))) is None:
                    self.received += len(data)
                    super().data_received(data)
                    return
                log.warning("closed a WebSocket connection: its message would take more "
                            "than %.0f MiB, and %s", (self.received + len(data)) / 2**20,
                            refused)
                # Failed, the library discards what comes (`data` too, never counted),
                # but holds the frames of the message read so far until the connection
                # is lost (they stay counted until then): the connection is closed now,
                # not when its client answers, which a hostile one never does.
                self.protocol.fail(CloseCode.MESSAGE_TOO_BIG, "the server is reading "
                                   "other clients' large messages: send it again later")
                super().data_received(data)  # writes the close frame
                self.transport.close()

        self.connection_class = Counted

    def serving(self) -> dict[str, Any]:
        """What `websockets.asyncio.server.serve` is given for these connections: made of
        `connection_class`, a message of MAX_MESSAGE bytes at most, one at a time, and
        without compression, so that the bytes received are those a message takes: with
        permessage-deflate a message of 64 MiB came as some 64 KiB, which was all that
        InFlight counted, and eight pages sending one at once took the studio to 1.1 GiB."""
        return {"create_connection": self.connection_class, "max_size": MAX_MESSAGE,
                "max_queue": 1, "compression": None, "logger": WEBSOCKETS_LOG}

    async def serve(self, connection: Any, new_session: Callable[[], Session]) -> None:
        """Serve `connection` (of `connection_class`) as a session of its own, one LSP
        message a WebSocket message, until it closes or the session exits."""
        from websockets.exceptions import ConnectionClosed
        from websockets.frames import CloseCode

        assert isinstance(connection, self.connection_class)
        sessions, in_flight = self.sessions, self.in_flight
        if len(sessions) >= MAX_SESSIONS:
            log.warning("a client beyond the %d served at once: refused", MAX_SESSIONS)
            fail_websocket(connection, CloseCode.TRY_AGAIN_LATER, BUSY)
            return
        session = new_session()
        sessions.add(session)
        writer = WebSocketOutbox(connection, functools.partial(in_flight.refusal, connection))
        session.attach(writer)
        try:
            with in_flight.counting(connection, lambda: connection.received + writer.unsent):
                async with _initialize_deadline(session, connection.transport.abort):
                    while session.exit_status is None:
                        # Not bound to a variable, which would keep it until the next.
                        connection.received = _hand_over(session,
                                                         await read_text(connection))
        except ConnectionClosed as closed:  # such as a message over MAX_MESSAGE
            log.info("a WebSocket connection ended: %s", closed)
        finally:
            sessions.discard(session)
            session.end()
            await writer.finish()
            # The exception that ended the library's parser (a client gone without
            # closing) keeps, through its traceback, the parser's variables, the last
            # frame read among them, in a reference cycle that only the garbage collector
            # frees, rarely on a quiet server: let go of them now.
            if (ended := connection.protocol.parser_exc) is not None:
                ended.__traceback__ = None
            self.collector.count()


async def serve_websocket(new_session: Callable[[], Session], host: str, port: int) -> None:
    """Serve each WebSocket connection to HOST:PORT as a session of its own, one LSP
    message a WebSocket message, until stopped. Needs the `websockets` package."""
    from websockets.asyncio.server import ServerConnection, serve

    lsp = WebSocketSessions()

    async def connected(connection: ServerConnection) -> None:
        await lsp.serve(connection, new_session)

    async with serve(connected, host, port, origins=[None, LOCAL_ORIGIN],
                     **lsp.serving()) as server:
        log.info("serving LSP over WebSocket on %s",
                 ", ".join(str(s.getsockname()) for s in server.sockets))
        await server.serve_forever()
