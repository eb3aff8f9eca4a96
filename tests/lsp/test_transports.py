"""`rl1-lsp --tcp` and `--ws` on real sockets: each connection is a session of its own
(its documents, its diagnostics, its `exit`), read with the same bounded reader as
standard input, and the server outlives every client and every kind of broken input."""

from __future__ import annotations

import contextlib
import json
from collections.abc import Iterator

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from raw import INITIALIZE, INITIALIZED, frame, notification, request
from sockets import Listening, TcpClient, listening

from rl1.lsp.transports import MAX_SESSIONS

PARSE_ERROR = -32700
REQUEST_FAILED = -32803


def did_open(uri: str, text: str, version: int = 1) -> bytes:
    return frame(notification("textDocument/didOpen", {"textDocument": {
        "uri": uri, "languageId": "rl1", "version": version, "text": text}}))


def hover(msg_id: int, uri: str = "file:///nowhere.rob") -> bytes:
    return frame(request(msg_id, "textDocument/hover", {
        "textDocument": {"uri": uri}, "position": {"line": 0, "character": 1}}))


@pytest.fixture(scope="module")
def tcp() -> Iterator[Listening]:
    with listening("tcp") as server:
        yield server


def session(server: Listening) -> TcpClient:
    """A fresh, initialized connection."""
    client = TcpClient(server.port)
    client.send(frame(INITIALIZE))
    assert "capabilities" in client.reply(1)["result"]
    client.send(frame(INITIALIZED))
    return client


def served(client: TcpClient, msg_id: int) -> None:
    client.send(hover(msg_id))
    assert client.reply(msg_id) == {"jsonrpc": "2.0", "id": msg_id, "result": None}


def test_two_connections_are_two_sessions_that_see_nothing_of_each_other(
        tcp: Listening) -> None:
    first = session(tcp)
    secret = "file:///home/first/secret.rob"
    first.send(did_open(secret, "A=(  ' the first client's source\n"))
    assert first.published()["uri"] == secret
    second = session(tcp)  # its initialize is answered, not refused
    second.send(hover(2, secret))
    assert second.reply(2)["result"] is None  # the first client's document is not its own
    # an edit of the first client's is published to it, and to it alone
    first.send(frame(notification("textDocument/didChange", {
        "textDocument": {"uri": secret, "version": 2}, "contentChanges": [{"text": "A=1\n"}]})))
    published = first.published()
    assert (published["uri"], published["version"]) == (secret, 2)
    second.send(hover(3))
    while (message := second.next()).get("id") != 3:
        assert secret not in json.dumps(message)
    first.close()
    second.close()


def test_the_server_outlives_a_client_that_exits_and_one_that_vanishes(tcp: Listening) -> None:
    leaving = session(tcp)
    leaving.send(frame(request(2, "shutdown")) + frame(notification("exit")))
    assert leaving.reply(2)["result"] is None
    assert leaving.closed()  # exit ends this session only
    session(tcp).close()  # vanishes without a word
    served(session(tcp), 2)


def test_a_content_length_bomb_is_skipped_in_bounded_memory(tcp: Listening) -> None:
    client = session(tcp)
    before = tcp.resident_mib()
    client.send(b"Content-Length: 99999999999\r\n\r\n")
    block = b"[" * 2**20
    for _ in range(128):  # 128 MiB streamed after the header
        client.send(block)
    client.send(b"\r\n\r\n")
    served(client, 2)  # the next framed message is read again
    assert tcp.resident_mib() - before < 64


@pytest.mark.parametrize("data", [
    b"x" * 200_000 + b"\r\n\r\n",  # a header line of 200 KB
    b"Content-Length: abc\r\n\r\n{}",
])
def test_broken_framing_is_skipped_and_the_connection_kept(tcp: Listening, data: bytes) -> None:
    client = session(tcp)
    client.send(data)
    served(client, 2)


@pytest.mark.parametrize("body", [b'{"jsonrpc": "2.0", "id": 2, "method": ', b"[" * 2000,
                                  b'{"jsonrpc": "2.0", "id": 2, "method": "x", "params": '
                                  + b"[" * 2000 + b"]" * 2000 + b"}"])
def test_malformed_or_deeply_nested_json_is_a_parse_error(tcp: Listening, body: bytes) -> None:
    client = session(tcp)
    client.send(frame(body))
    assert client.reply(None)["error"]["code"] == PARSE_ERROR
    served(client, 3)


def test_connections_beyond_the_limit_are_refused_clearly(tcp: Listening) -> None:
    clients = [session(tcp) for _ in range(MAX_SESSIONS)]
    extra = TcpClient(tcp.port)
    extra.send(frame(INITIALIZE))
    error = extra.reply(1)["error"]
    assert error["code"] == REQUEST_FAILED
    assert f"{MAX_SESSIONS} clients" in error["message"] and "close" in error["message"]
    assert extra.closed()
    clients.pop().close()
    for _ in range(50):  # the server notices the closed connection soon
        retry = TcpClient(tcp.port)
        retry.send(frame(INITIALIZE))
        if "result" in retry.reply(1):
            break
    else:
        pytest.fail("a closed session's place was not given to a new client")
    for client in clients:
        served(client, 9)


pieces = st.one_of(
    st.binary(max_size=300),
    st.sampled_from([frame(INITIALIZE), frame(INITIALIZED), hover(7), b"Content-Length: ",
                     b"\r\n\r\n", b"Content-Length: 99999999999\r\n\r\n", b"[" * 3000,
                     frame(request(8, "shutdown")), frame(notification("exit"))]))


@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(pieces, max_size=12))
def test_whatever_a_client_sends_the_next_one_is_served(tcp: Listening,
                                                          sent: list[bytes]) -> None:
    hostile = TcpClient(tcp.port)
    with contextlib.suppress(OSError):
        for piece in sent:
            hostile.send(piece)
    hostile.close()
    client = session(tcp)
    served(client, 2)
    client.close()


def test_the_server_still_runs_and_wrote_no_traceback(tcp: Listening) -> None:
    """Run last in this module: everything above left it running, and no traceback."""
    assert tcp.process.poll() is None
    assert "Traceback" not in tcp.stderr()
