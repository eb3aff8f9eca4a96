"""What the studio's server refuses as the protocols ask (spec/studio.md, "Routes"): a
binary WebSocket message (close code 1003), a text message not in UTF-8 (1007), a page
that sends nothing (closed after INITIALIZE_SECONDS, as `/lsp` closes a connection that
sends no initialize), and an HTTP request it cannot read (400, or the library's 414 and
431), each said in one line of the log."""

from __future__ import annotations

import contextlib
import logging
import time
from collections.abc import Iterator

import pytest
from served import TIMEOUT, Served, page, sample_folder, serving
from support.hostile import UNREADABLE_REQUESTS, http_answer
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from rl1.lsp import transports

SOCKETS = ["/lsp", "/studio"]


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Served]:
    with serving(sample_folder(tmp_path_factory.mktemp("refusals"))) as server:
        yield server


def _warnings(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [record.getMessage() for record in caplog.records
            if record.levelno == logging.WARNING]


def _closed(served: Served, path: str, message: bytes, text: bool) -> tuple[int, str]:
    """The close code and reason with which the server answers `message` on `path`."""
    with connect(served.url(path, scheme="ws"), open_timeout=TIMEOUT) as client:
        client.send(message, text=text)
        with pytest.raises(ConnectionClosed) as closed:
            client.recv(timeout=TIMEOUT)
    assert closed.value.rcvd is not None, "closed without a close frame"
    return closed.value.rcvd.code, closed.value.rcvd.reason


@pytest.mark.parametrize("path", SOCKETS)
def test_a_binary_message_closes_its_connection_with_1003(
        served: Served, path: str, caplog: pytest.LogCaptureFixture) -> None:
    """RFC 6455 7.4.1: the page sends text only; a binary message was read as JSON."""
    request = b'{"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": {}}'
    code, reason = _closed(served, path, request, text=False)
    assert code == 1003 and "send each message as a text message" in reason
    assert [said for said in _warnings(caplog) if "(1003)" in said] == [
        "closed a WebSocket connection (1003): it sent a binary message, where JSON-RPC "
        "comes in text messages"]


@pytest.mark.parametrize("path", SOCKETS)
def test_a_text_message_not_in_utf8_closes_its_connection_with_1007(
        served: Served, path: str, caplog: pytest.LogCaptureFixture) -> None:
    """RFC 6455 8.1: it was answered as a JSON-RPC parse error, the connection kept."""
    sent = b'{"jsonrpc": "2.0", "id": 1, "method": "\xc3("}'
    where = f"invalid continuation byte at byte {sent.index(0xc3)}"
    code, reason = _closed(served, path, sent, text=True)
    assert code == 1007
    assert reason == f"a text message not in UTF-8 ({where}): send text in UTF-8"
    assert [said for said in _warnings(caplog) if "(1007)" in said] == [
        f"closed a WebSocket connection (1007): a text message not in UTF-8 ({where})"]


@pytest.mark.parametrize("path", SOCKETS)
def test_connections_that_say_nothing_are_closed_after_the_deadline(
        served: Served, path: str, monkeypatch: pytest.MonkeyPatch,
        caplog: pytest.LogCaptureFixture) -> None:
    """Eight pages that opened /studio and said nothing held every place for as long as
    they stayed; /lsp's connections had INITIALIZE_SECONDS to send initialize. A page
    that has spoken stays past the deadline."""
    monkeypatch.setattr(transports, "INITIALIZE_SECONDS", 0.2)
    with contextlib.ExitStack() as stack:
        silent = [stack.enter_context(connect(served.url(path, scheme="ws"),
                                              open_timeout=TIMEOUT))
                  for _ in range(transports.MAX_SESSIONS)]
        for connection in silent:
            with pytest.raises(ConnectionClosed):
                connection.recv(timeout=TIMEOUT)
    with page(served) as speaking:
        speaking.request("initialize")
        time.sleep(0.4)  # past its deadline
        assert speaking.request("initialize")["program"] is None
    said = "a page sent no message" if path == "/studio" else "a client sent no initialize"
    assert _warnings(caplog) == [f"{said} in 0 s: disconnected"] * transports.MAX_SESSIONS


@pytest.mark.parametrize("sent", UNREADABLE_REQUESTS)
def test_a_request_it_cannot_read_is_answered(served: Served, sent: str,
                                              caplog: pytest.LogCaptureFixture) -> None:
    """A body, a request line not in ASCII, a line it cannot split: the connection was
    closed without an answer, which an HTTP client reports as a server's failure."""
    request, status = UNREADABLE_REQUESTS[sent]
    answered, text = http_answer(served.port, request)
    assert answered == status, text
    assert text.endswith(".\n") and len(text) < 200, text
    if status == 400:
        what = text.removeprefix("Bad request: ").removesuffix(".\n")
        assert _warnings(caplog) == [
            f"answered 400 Bad Request to an HTTP request it cannot read: {what}"]
