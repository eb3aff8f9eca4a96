"""`rl1-lsp --tcp` and `--ws` under the hostile harness (tests/support/hostile.py;
bench/hostile_fuzz.py runs the same attacks for as long as asked): whatever a client
sends (broken framing, Content-Length bombs and lies, nested or malformed JSON, hostile
parameters and documents, WebSocket frames of the wrong type, oversize or fragmented, a
wrong Origin, an opening request it cannot read, half-closed sockets, many connections
at once), the next client is served, hears nothing of the other sessions, and the server
stays alive in bounded memory. And connections that send nothing cannot hold every
place."""

from __future__ import annotations

import contextlib
import functools
import json
import logging
import re
import socket
import time
from collections.abc import Iterator

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.hostile import (
    GROWTH_BOUND_MIB,
    INITIALIZE,
    HostileConnection,
    ServedLsp,
    _frame,
    _send_hostile,
    hostile_connections,
    large_messages_at_once,
    serve_one_after_another,
    transport_attack,
    ws_frame,
    ws_handshake,
)
from support.memory import at_once, kept_mib, settled_mib

from rl1.lsp.framing import MAX_MESSAGE
from rl1.lsp.transports import INITIALIZE_SECONDS, MAX_SESSIONS, MEMORY_IN_FLIGHT

pytest.importorskip("websockets")
TRANSPORTS = ["tcp", "ws"]


@pytest.fixture(scope="module", params=TRANSPORTS)
def server(request: pytest.FixtureRequest) -> Iterator[ServedLsp]:
    served = ServedLsp(request.param)
    try:
        yield served
    finally:
        served.stop()


@settings(max_examples=30, deadline=None, database=None,
          suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_after_any_hostile_client_the_next_one_is_served(server: ServedLsp,
                                                         data: st.DataObject) -> None:
    attack = data.draw(hostile_connections(server.transport))
    assert transport_attack(server, attack) == []


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_the_harness_finds_a_server_that_died(transport: str) -> None:
    """The property above can fail: a dead server is a problem (and is started again)."""
    server = ServedLsp(transport)
    try:
        server.process.kill()
        server.process.wait()
        found = transport_attack(server, HostileConnection(chunks=(b"",)))
        assert any("not served" in problem for problem in found), found
        assert any("ended with status" in problem for problem in found), found
        assert transport_attack(server, HostileConnection(chunks=(b"",))) == []
    finally:
        server.stop()


KNOWN_HARD = {
    "tcp": [b"X: " + b"y" * 200_000 + b"\r\n\r\n", b"Content-Length: 99999999999\r\n\r\n"
            + b"[" * 2**23, b"Content-Length: 10\r\n\r\n" + b"[" * 5000],
    "ws": [ws_frame(1, b"", told=2**63 - 1), ws_frame(2, b"[" * 5000),
           ws_frame(3, b"{}"), ws_frame(1, b"{", fin=False) + ws_frame(1, b"}")],
}


# Named by place, not by their bytes: a WebSocket frame's mask is random, and the workers
# of pytest-xdist must collect the same names.
@pytest.mark.parametrize(("transport", "sent"), [
    pytest.param(transport, sent, id=f"{transport}-{index}")
    for transport, attacks in KNOWN_HARD.items() for index, sent in enumerate(attacks)])
def test_known_hard_inputs(transport: str, sent: bytes) -> None:
    server = ServedLsp(transport)
    try:
        assert transport_attack(server, HostileConnection(chunks=(sent,), copies=7)) == []
    finally:
        server.stop()


def _largest_message(transport: str, fragments: int = 1) -> tuple[bytes, ...]:
    """An initialize, then a request of MAX_MESSAGE bytes (a string of "a"s, id 2), which
    the server reads and decodes whole, and answers: on TCP its headers, then the body in
    pieces; on a WebSocket in `fragments` frames."""
    head = b'{"jsonrpc":"2.0","id":2,"method":"x","params":"'
    body = head + b"a" * (MAX_MESSAGE - len(head) - 2) + b'"}'
    if transport == "ws":
        size = -(-len(body) // fragments)
        frames = [ws_frame(0 if start else 1, body[start:start + size],
                           fin=start + size >= len(body))
                  for start in range(0, len(body), size)]
        return ws_frame(1, json.dumps(INITIALIZE).encode()), *frames
    pieces = [body[start:start + 2**20] for start in range(0, len(body), 2**20)]
    return _frame(INITIALIZE), b"Content-Length: %d\r\n\r\n" % len(body), *pieces


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_eight_clients_sending_the_largest_message_at_once_stay_in_the_bound(
        transport: str) -> None:
    """Issue 23: each session read a message of MAX_MESSAGE bytes whatever the others
    held, and kept the last one it read, so that eight grew the server by 577 MiB (the
    campaign) to 1 GiB and more; the bytes in flight of all sessions are now bounded
    together, those beyond refused, and the other clients are served."""
    server = ServedLsp(transport)
    attack = HostileConnection(chunks=_largest_message(transport))
    connections: list[socket.socket | None] = []
    try:
        at_once(MAX_SESSIONS, lambda: connections.append(_send_hostile(server, attack)))
        for connection in connections:
            if connection is not None:
                connection.close()
        peak = server.peak_mib() - server.started_mib
        assert peak < GROWTH_BOUND_MIB, f"{peak:.0f} MiB at its peak"
        assert transport_attack(server, HostileConnection(chunks=(b"",), copies=0)) == []
    finally:
        server.stop()


@pytest.mark.parametrize(("transport", "fragments"), [("tcp", 1), ("ws", 1), ("ws", 4)])
def test_more_clients_than_are_served_sending_the_largest_message_stay_in_the_bound(
        transport: str, fragments: int) -> None:
    """Issue 23: twelve WebSocket clients sending MAX_MESSAGE bytes took the server to
    370-394 MiB (627 in the campaign), for good: the four beyond those served were read
    while their refusal waited for an answer, counted nowhere; a message refused for
    the budget was held, no longer counted, until its client answered; and glibc kept
    the room of the freed frames in its heap. At its peak the server stays within what
    its messages may take (MEMORY_IN_FLIGHT), and once the clients have left it holds
    none of it."""
    server = ServedLsp(transport)
    attack = HostileConnection(chunks=_largest_message(transport, fragments))
    connections: list[socket.socket | None] = []
    try:
        at_once(MAX_SESSIONS + 4, lambda: connections.append(_send_hostile(server, attack)))
        for connection in connections:
            if connection is not None:
                connection.close()
        assert transport_attack(server, HostileConnection(chunks=(b"",), copies=0)) == []
        # The one message read whole (transports.InFlight's reservation) may still be
        # read or decoded once the others are done: on a loaded machine 65 MiB were
        # held just after the client that came next was served.
        kept = settled_mib(lambda: server.resident_mib() - server.started_mib,
                           MAX_MESSAGE / 2**20)
        assert kept < MAX_MESSAGE / 2**20, f"{kept:.0f} MiB kept after the clients left"
        peak = server.peak_mib() - server.started_mib
        assert peak < MEMORY_IN_FLIGHT / 2**20, f"{peak:.0f} MiB at its peak"
    finally:
        server.stop()


def test_websocket_clients_sending_compressed_messages_at_once_stay_in_the_bound() -> None:
    """Found by the studio's hostile pass: with permessage-deflate a message of 60 MiB
    came as some 60 KiB, which is all the bound of the bytes in flight counted, and the
    server inflated and read every client's at once. The server now takes no
    compression: what it receives is what a message takes. And one of the eight is
    always read and answered, whatever the others send meanwhile."""
    server = ServedLsp("ws")
    try:
        answered = large_messages_at_once(server)
        peak = server.peak_mib() - server.started_mib
        assert peak < GROWTH_BOUND_MIB, f"{peak:.0f} MiB at its peak"
        # However their frames interleave, the first to need more than its free share
        # has its message read (transports.InFlight's reservation): on a loaded machine
        # each was refused midway, none answered, before it.
        assert answered and all('"capabilities"' in answer for answer in answered)
        assert transport_attack(server, HostileConnection(chunks=(b"",), copies=0)) == []
    finally:
        server.stop()


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_a_server_keeps_no_message_of_the_clients_that_have_left(transport: str) -> None:
    """Issue 23: a session kept its last message after it ended (in a coroutine's
    variable, a connection reset's reference cycle, pygls' cache of 128 sessions, the
    WebSocket library's parser), so that eight clients one after the other grew the
    server by eight messages of MAX_MESSAGE bytes."""
    server = ServedLsp(transport)
    attack = HostileConnection(chunks=_largest_message(transport))
    try:
        for _ in range(MAX_SESSIONS):
            connection = _send_hostile(server, attack)
            assert connection is not None
            with connection:  # the answer to the message says that it has been handled
                heard = b""
                while not re.search(rb'"id":\s*2\b', heard):
                    chunk = connection.recv(65536)
                    assert chunk, f"the server closed the connection: {server.stop()[-300:]}"
                    heard += chunk
        assert transport_attack(server, HostileConnection(chunks=(b"",), copies=0)) == []
        kept = server.resident_mib() - server.started_mib
        assert kept < MAX_MESSAGE / 2**20, f"{kept:.0f} MiB kept after the clients left"
    finally:
        server.stop()


KEPT_BY_200_CLIENTS_MIB = 16
"""What 200 clients served one after another may leave the server holding: what its
allocator keeps, some 0.08 MiB a client (an ended session took 0.31 MiB, for good)."""


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_clients_one_after_another_leave_nothing_behind(transport: str) -> None:
    """Issue 23: every ended session stayed in memory, 0.31 MiB each, since the front
    end's pauses of the garbage collector put it where CPython seldom collects, so
    that after about 1,000 clients the server passed the hostile harness's bound."""
    server = ServedLsp(transport)
    try:
        kept = kept_mib(functools.partial(serve_one_after_another, server),
                        server.resident_mib, 200)
        assert kept < KEPT_BY_200_CLIENTS_MIB, f"{kept:.1f} MiB kept by 200 clients"
    finally:
        server.stop()


def test_a_session_that_ends_gives_back_its_documents_analysis() -> None:
    """An ended session's documents, freed only with its reference cycles, were kept
    until the garbage collector ran: after a client had checked a program of 30,000
    lines and left, the server kept half of what it had taken at its peak."""
    server = ServedLsp("tcp")
    program = "".join(f"L{number}: A=A+{number}\n" for number in range(30_000))
    opened = {"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {
        "uri": "file:///large.rob", "languageId": "rl1", "version": 1, "text": program}}}
    try:
        with socket.create_connection(("127.0.0.1", server.port), timeout=60) as client:
            client.sendall(_frame(INITIALIZE) + _frame(opened))
            heard = b""
            while b"textDocument/publishDiagnostics" not in heard:
                chunk = client.recv(65536)
                assert chunk, f"the server closed the connection: {server.stop()[-300:]}"
                heard += chunk
        assert transport_attack(server, HostileConnection(chunks=(b"",), copies=0)) == []
        peak = server.peak_mib() - server.started_mib
        kept = server.resident_mib() - server.started_mib
        assert kept < peak / 4, f"{kept:.0f} MiB kept of {peak:.0f} at the peak"
    finally:
        server.stop()


def _silent(server: ServedLsp) -> socket.socket:
    """A connection that opens (on a WebSocket, completes the handshake) and says nothing."""
    connection = socket.create_connection(("127.0.0.1", server.port), timeout=30)
    if server.transport == "ws":
        connection.sendall(ws_handshake(server.port, None))
        assert connection.recv(4096).startswith(b"HTTP/1.1 101")
    return connection


def _closed_within(connection: socket.socket, seconds: float) -> bool:
    """Whether the server closes `connection` within `seconds` (what it sends before, a
    WebSocket's close frame, read and dropped)."""
    deadline = time.monotonic() + seconds
    try:
        while (left := deadline - time.monotonic()) > 0:
            connection.settimeout(left)
            if not connection.recv(4096):
                return True
    except ConnectionResetError:  # closed with unread data, or aborted
        return True
    except TimeoutError:
        pass
    return False


@pytest.mark.parametrize("transport", TRANSPORTS)
def test_connections_that_send_no_initialize_do_not_hold_every_place(transport: str) -> None:
    """Eight connections that said nothing once kept every other client out for as long
    as they stayed open."""
    server = ServedLsp(transport)
    try:
        with contextlib.ExitStack() as stack:
            silent = [stack.enter_context(_silent(server)) for _ in range(MAX_SESSIONS)]
            # Closed INITIALIZE_SECONDS after each opened; the rest is room for a load.
            assert all(_closed_within(connection, INITIALIZE_SECONDS + 60)
                       for connection in silent), server.stop()[-300:]
            assert transport_attack(server, HostileConnection(chunks=(b"",), copies=0)) == []
    finally:
        server.stop()



def test_an_error_the_websocket_library_logs_is_one_line(
        capsys: pytest.CaptureFixture[str]) -> None:
    """The campaign found the websockets library logging a traceback ("unexpected internal
    error", an assertion in its send_eof) when a client half-closed its socket while the
    server refused its opening handshake; the server went on, but wrote a traceback."""
    handler = logging.StreamHandler()  # to standard error, as rl1-lsp logs
    # the logger serve_websocket gives the library
    websockets_log = logging.getLogger("rl1.lsp.transports.websockets")
    websockets_log.addHandler(handler)
    try:
        try:
            raise AssertionError("send_eof")
        except AssertionError:
            websockets_log.error("unexpected internal error", exc_info=True)
    finally:
        websockets_log.removeHandler(handler)
    said = capsys.readouterr().err
    assert "Traceback" not in said
    assert "unexpected internal error (AssertionError: send_eof)" in said


def test_a_websocket_client_that_pings_and_never_reads_holds_no_more_memory() -> None:
    """Found by the hostile pass: the websockets library answers each ping as it reads it,
    into the connection's buffer, whatever is still unread there, so a client that sent
    pings and never read grew the server without bound (with a message now and then,
    which keeps its count of the bytes received low: 320 MiB of pings, 285 MiB more
    held). Now the server reads no more from a client while what it wrote is unread."""
    server = ServedLsp("ws")
    flood = ws_frame(9, b"p" * 125) * 2000 + ws_frame(1, json.dumps(
        {"jsonrpc": "2.0", "method": "$/cancelRequest", "params": {"id": 1}}).encode())
    try:
        with socket.socket() as client:
            client.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # reads nothing
            client.connect(("127.0.0.1", server.port))
            client.sendall(ws_handshake(server.port, None))
            client.sendall(ws_frame(1, json.dumps(INITIALIZE).encode()))
            client.settimeout(2)  # the server reads no more: the flood stops here
            with contextlib.suppress(TimeoutError):
                for _ in range(64 * 2**20 // len(flood)):
                    client.sendall(flood)
            grown = server.peak_mib() - server.started_mib
        assert grown < 24, f"the server grew by {grown:.0f} MiB"
        assert transport_attack(server, HostileConnection(chunks=(b"",), copies=0)) == []
    finally:
        server.stop()
