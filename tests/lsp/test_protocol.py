"""The JSON-RPC and LSP rules over the server's real standard input and output: broken
framing is skipped up to the next valid header, a message has a bounded size, errors
carry the codes JSON-RPC and LSP give them, and the session's start and end follow
LSP; after a burst of edits, the last diagnostics published are the last version's."""

from __future__ import annotations

import asyncio
import json
import time
from collections.abc import Iterator
from typing import Any

import pytest
from raw import INITIALIZE, INITIALIZED, RawServer, frame, notification, request

from rl1.lsp.server import create_server

PARSE_ERROR = -32700
INVALID_REQUEST = -32600
INVALID_PARAMS = -32602
SERVER_NOT_INITIALIZED = -32002

HOVER_NOWHERE = {"textDocument": {"uri": "file:///never/opened.rob"},
                 "position": {"line": 0, "character": 0}}


@pytest.fixture
def server() -> Iterator[RawServer]:
    running = RawServer()
    yield running
    running.kill()


def hover(msg_id: int) -> bytes:
    return frame(request(msg_id, "textDocument/hover", HOVER_NOWHERE))


def answered(server: RawServer, msg_id: int) -> None:
    """The server answers a request sent now, with a result."""
    server.send(hover(msg_id))
    assert "error" not in server.reply(msg_id)


# Framing --------------------------------------------------------------------------------

@pytest.mark.parametrize("header", [
    b"Content-Length: 99999999999999\r\n\r\n",
    b"Content-Length: 67108865\r\n\r\n",  # one byte more than the limit
    b"Content-Type: application/vscode-jsonrpc\r\n\r\n",  # no Content-Length
    b"Content-Length: -5\r\n\r\n",
    b"Content-Length: abc\r\n\r\n",
    b"Content-Length: 12 34\r\n\r\n",
    b"x" * 100_000 + b"\r\n\r\n",  # a header line longer than any header
])
def test_a_message_with_a_broken_header_is_skipped_up_to_the_next_one(
        server: RawServer, header: bytes) -> None:
    server.start()
    server.send(frame(request(2, "textDocument/hover", HOVER_NOWHERE), header))
    answered(server, 3)
    answered(server, 4)
    server.send(frame(request(5, "shutdown")) + frame(notification("exit")))
    assert server.reply(5)["result"] is None
    status, stderr = server.finish()
    assert status == 0
    assert "skipped" in stderr


def test_line_feeds_alone_frame_messages_too(server: RawServer) -> None:
    server.start()
    body = json.dumps(request(2, "textDocument/hover", HOVER_NOWHERE)).encode()
    server.send(b"Content-Length: %d\n\n" % len(body) + body)
    assert server.reply(2)["result"] is None
    answered(server, 3)


def test_a_header_split_across_writes_is_read_whole(server: RawServer) -> None:
    server.start()
    data = hover(2) + hover(3)
    for start in range(0, len(data), 7):
        server.send(data[start:start + 7])
        time.sleep(0.001)
    assert server.reply(2)["result"] is None
    assert server.reply(3)["result"] is None


# JSON-RPC errors ------------------------------------------------------------------------

@pytest.mark.parametrize("body", [b'{"jsonrpc": "2.0", "id": 2, "method": ', b"\xff\xfe{}",
                                  b"", b"[" * 2000, b'{"a": ' * 100_000])
def test_malformed_json_is_a_parse_error(server: RawServer, body: bytes) -> None:
    server.start()
    server.send(frame(body))
    reply = server.reply(None)
    assert reply["error"]["code"] == PARSE_ERROR
    answered(server, 3)


@pytest.mark.parametrize("number", [b"NaN", b"Infinity", b"-Infinity", b"1e400"])
def test_nan_and_infinity_are_no_json(server: RawServer, number: bytes) -> None:
    """Found by the studio's hostile pass: Python's json reads them, and a request with
    the id NaN was answered with `"id": NaN`, which no client's JSON reader reads."""
    server.start()
    server.send(frame(b'{"jsonrpc": "2.0", "id": %s, "method": "shutdown"}' % number))
    reply = server.next()
    assert reply["id"] is None and reply["error"]["code"] == PARSE_ERROR, reply
    assert number.lstrip(b"-").decode() in reply["error"]["message"]
    answered(server, 3)


@pytest.mark.parametrize("body", [b"[]", b"42", b'"hover"', b'{"id": 2, "method": "shutdown"}'])
def test_json_that_is_no_message_is_an_invalid_request(server: RawServer, body: bytes) -> None:
    server.start()
    server.send(frame(body))
    msg_id = 2 if b'"id"' in body else None
    assert server.error_code(msg_id) == INVALID_REQUEST
    answered(server, 3)


@pytest.mark.parametrize("method", [[1], {"name": "x" * 10_000}, 42, None, True])
@pytest.mark.parametrize("msg_id", [2, None])
def test_a_method_that_is_no_string_is_an_invalid_request(
        server: RawServer, method: object, msg_id: int | None) -> None:
    """JSON-RPC's method is a string: another was answered Internal Error (-32603), a
    message saying neither what was wrong nor what to send (1da3154 answered only an
    unknown string)."""
    server.start()
    message: dict[str, object] = {"jsonrpc": "2.0", "method": method, "params": {}}
    if msg_id is not None:
        message["id"] = msg_id
    server.send(frame(json.dumps(message).encode()))
    error = server.reply(msg_id)["error"]
    assert error["code"] == INVALID_REQUEST, error
    assert error["message"].startswith("`method` is "), error
    assert len(error["message"]) < 200, error
    answered(server, 3)


def test_params_that_do_not_fit_are_answered_with_where_and_no_traceback(
        server: RawServer) -> None:
    server.start()
    server.send(frame(request(2, "textDocument/hover", {
        "textDocument": {"uri": "file:///a.rob"}, "position": {"line": "one", "character": 0}})))
    error = server.reply(2)["error"]
    assert error["code"] == INVALID_PARAMS
    assert "textDocument/hover" in error["message"] and "$.params.position.line" in error["message"]
    server.send(frame(notification("textDocument/didChange", {"textDocument": 1})))
    answered(server, 3)
    server.send(frame(request(4, "shutdown")) + frame(notification("exit")))
    status, stderr = server.finish()
    assert status == 0 and "Traceback" not in stderr
    assert "dropped a message that does not fit LSP: textDocument/didChange" in stderr


def test_a_request_refused_on_purpose_is_answered_with_no_traceback(server: RawServer) -> None:
    server.start()
    uri = "file:///a.rob"
    server.send(frame(notification("textDocument/didOpen", {"textDocument": {
        "uri": uri, "languageId": "rl1", "version": 1, "text": "A=1\n"}})))
    server.send(frame(request(2, "textDocument/rename", {
        "textDocument": {"uri": uri}, "position": {"line": 0, "character": 0},
        "newName": "12"})))
    assert "only labels can be renamed" in server.reply(2)["error"]["message"]
    server.send(frame(request(3, "workspace/executeCommand", {"command": "rl1.nothing"})))
    assert server.error_code(3) == INVALID_PARAMS
    server.send(frame(request(4, "shutdown")) + frame(notification("exit")))
    status, stderr = server.finish()
    assert status == 0 and "Traceback" not in stderr, stderr


# The session: initialize first, shutdown, exit --------------------------------------------

def test_a_request_before_initialize_is_refused(server: RawServer) -> None:
    server.send(hover(7))
    assert server.error_code(7) == SERVER_NOT_INITIALIZED
    server.send(frame(notification("textDocument/didOpen", {"textDocument": {
        "uri": "file:///early.rob", "languageId": "rl1", "version": 1, "text": "A=("}})))
    server.start()  # the notification before initialize was dropped: nothing published
    answered(server, 8)
    assert server.messages.empty()


def test_after_shutdown_requests_are_invalid_and_exit_succeeds(server: RawServer) -> None:
    server.start()
    server.send(frame(request(2, "shutdown")))
    assert server.reply(2)["result"] is None
    server.send(hover(3))
    assert server.error_code(3) == INVALID_REQUEST
    server.send(frame(notification("exit")))
    status, stderr = server.finish()
    assert status == 0
    assert "hover after shutdown" in stderr and "Traceback" not in stderr


def test_exit_without_shutdown_fails(server: RawServer) -> None:
    server.start()
    server.send(frame(notification("exit")))
    status, _ = server.finish()
    assert status == 1


def test_exit_before_initialize_fails(server: RawServer) -> None:
    server.send(frame(notification("exit")))
    status, _ = server.finish()
    assert status == 1


def test_initialize_twice_is_an_invalid_request(server: RawServer) -> None:
    server.start()
    server.send(frame({**INITIALIZE, "id": 2}))
    assert server.error_code(2) == INVALID_REQUEST
    server.send(frame(INITIALIZED))
    answered(server, 3)


# Bursts ---------------------------------------------------------------------------------

def test_after_a_burst_the_last_diagnostics_published_are_the_last_versions(
        server: RawServer) -> None:
    server.start()
    lines = [f"A=B+{n % 100}" for n in range(2_000)]
    uri = "file:///burst.rob"
    server.send(frame(notification("textDocument/didOpen", {"textDocument": {
        "uri": uri, "languageId": "rl1", "version": 1, "text": "\n".join(lines)}})))
    burst = bytearray()
    last = 301
    for version in range(2, last + 1):
        line = version * 7 % len(lines)
        text = "A=(" if version % 3 else "B=A+1"  # errors come and go
        burst += frame(notification("textDocument/didChange", {
            "textDocument": {"uri": uri, "version": version},
            "contentChanges": [{"range": {"start": {"line": line, "character": 0},
                                          "end": {"line": line,
                                                  "character": len(lines[line])}},
                                "text": text}]}))
        lines[line] = text
    server.send(bytes(burst))
    published: list[dict[str, Any]] = []
    while not published or published[-1]["version"] != last:
        message = server.next()
        if message.get("method") == "textDocument/publishDiagnostics":
            published.append(message["params"])
    # a fresh document with the final text: what the last version's diagnostics are
    server.send(frame(notification("textDocument/didOpen", {"textDocument": {
        "uri": "file:///final.rob", "languageId": "rl1", "version": 1,
        "text": "\n".join(lines)}})))
    while (message := server.next()).get("params", {}).get("uri") != "file:///final.rob":
        published.append(message["params"])
    assert [p["version"] for p in published].index(last) == len(published) - 1
    assert published[-1]["diagnostics"] == message["params"]["diagnostics"]
    assert len(published[-1]["diagnostics"]) == lines.count("A=(")


class Discarded:
    """A transport's writer that drops what the session writes."""

    def write(self, data: bytes) -> None:
        pass

    def close(self) -> None:
        pass


def test_handled_notifications_leave_nothing_behind() -> None:
    """pygls 2.1.1 files the future of each notification its dispatch runs under an id
    that no response removes: the session hands notifications to their handlers itself,
    or every edit would cost memory for the whole session."""
    session = create_server()
    session.attach(Discarded())

    def receive(message: dict[str, Any]) -> None:
        session.receive(json.dumps(message).encode())

    async def run() -> int:
        receive(INITIALIZE)
        receive(INITIALIZED)
        receive(notification("textDocument/didOpen", {"textDocument": {
            "uri": "file:///a.rob", "languageId": "rl1", "version": 1, "text": "A=1\n"}}))
        for version in range(2, 202):
            receive(notification("textDocument/didChange", {
                "textDocument": {"uri": "file:///a.rob", "version": version},
                "contentChanges": [{"text": f"A={version}\n"}]}))
            receive(notification("$/setTrace", {"value": "off"}))
            receive(INITIALIZED)
        await asyncio.sleep(0.1)
        return len(session.protocol._request_futures)

    assert asyncio.run(run()) == 0
