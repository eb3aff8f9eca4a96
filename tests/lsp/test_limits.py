"""What one session holds is bounded: a document opened past the limit of open documents,
or of their characters in all, is turned away with a notice that says what to do, and
one that grows past it is dropped; closing documents makes room again. The session is
driven in the process, through the interface a transport uses, with small limits."""

from __future__ import annotations

import asyncio
import json
from collections.abc import Callable, Coroutine
from typing import Any

import pytest
from raw import INITIALIZE, INITIALIZED, notification

from rl1.lsp import server as server_module
from rl1.lsp.document import MAX_ANALYSED_LINE
from rl1.lsp.server import create_server

Message = dict[str, Any]


class Collected:
    """A transport's writer that keeps every message the session writes."""

    def __init__(self) -> None:
        self.messages: list[Message] = []

    def write(self, data: bytes) -> None:
        self.messages.append(json.loads(data))

    def close(self) -> None:
        pass

    def published(self, uri: str) -> list[Message]:
        return [m["params"] for m in self.messages
                if m.get("method") == "textDocument/publishDiagnostics"
                and m["params"]["uri"] == uri]


Scenario = Callable[[Callable[[Message], None], Collected], Coroutine[Any, Any, None]]


def run_session(scenario: Scenario) -> None:
    session = create_server()
    written = Collected()

    def send(message: Message) -> None:
        session.receive(json.dumps(message).encode())

    async def main() -> None:
        session.attach(written)
        send(INITIALIZE)
        send(INITIALIZED)
        await scenario(send, written)
        session.end()

    asyncio.run(main())


def did_open(uri: str, text: str) -> Message:
    return notification("textDocument/didOpen", {"textDocument": {
        "uri": uri, "languageId": "rl1", "version": 1, "text": text}})


def did_close(uri: str) -> Message:
    return notification("textDocument/didClose", {"textDocument": {"uri": uri}})


async def settle() -> None:
    await asyncio.sleep(0.05)  # the checks scheduled run


def turned_away(written: Collected, uri: str, limit: str = "") -> bool:
    """Whether the last diagnostics of `uri` say it is over a limit (naming `limit`)."""
    published = written.published(uri)
    return bool(published) and any(
        "holds at most" in d["message"] and limit in d["message"]
        and "Close some documents and reopen this one" in d["message"]
        for d in published[-1]["diagnostics"])


@pytest.fixture
def small_limits(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(server_module, "MAX_OPEN_DOCUMENTS", 3)
    monkeypatch.setattr(server_module, "MAX_OPEN_CHARACTERS", 1000)
    monkeypatch.setattr(server_module, "MAX_ANALYSED_IN_ALL", 1000)


@pytest.mark.usefixtures("small_limits")
def test_a_document_past_the_count_is_turned_away_until_another_closes() -> None:
    async def scenario(send: Callable[[Message], None], written: Collected) -> None:
        for n in range(4):
            send(did_open(f"file:///d{n}.rob", "A=(\n"))
        await settle()
        assert [turned_away(written, f"file:///d{n}.rob", "3 open documents")
                for n in range(4)] == [False, False, False, True]
        send(did_close("file:///d0.rob"))
        send(did_open("file:///d3.rob", "A=(\n"))
        await settle()
        assert any(d.get("code") == "E0101" for d in
                   written.published("file:///d3.rob")[-1]["diagnostics"])

    run_session(scenario)


@pytest.mark.usefixtures("small_limits")
def test_characters_past_the_limit_turn_away_an_open_and_drop_a_change() -> None:
    async def scenario(send: Callable[[Message], None], written: Collected) -> None:
        send(did_open("file:///big.rob", "A=1\n" * 200))  # 800 characters
        send(did_open("file:///more.rob", "A=1\n" * 60))  # 1,040 in all
        await settle()
        assert turned_away(written, "file:///more.rob")
        assert not turned_away(written, "file:///big.rob")
        send(notification("textDocument/didChange", {
            "textDocument": {"uri": "file:///big.rob", "version": 2},
            "contentChanges": [{"text": "A=1\n" * 300}]}))
        await settle()
        assert turned_away(written, "file:///big.rob")
        send(did_open("file:///more.rob", "A=1\n" * 60))  # now there is room
        await settle()
        assert not turned_away(written, "file:///more.rob")

    run_session(scenario)


def test_a_document_too_large_to_analyse_counts_only_its_characters(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(server_module, "MAX_ANALYSED_IN_ALL", 1000)
    long_line = "A=1;" * (MAX_ANALYSED_LINE // 4 + 1) + "\n"  # kept in sync, not analysed

    async def scenario(send: Callable[[Message], None], written: Collected) -> None:
        send(did_open("file:///long.rob", long_line))
        send(did_open("file:///small.rob", "A=1\n" * 200))
        await settle()
        assert not turned_away(written, "file:///long.rob")
        assert not turned_away(written, "file:///small.rob")
        send(did_open("file:///more.rob", "A=1\n" * 60))
        await settle()
        assert turned_away(written, "file:///more.rob",
                           "1,000 characters in all the documents it analyses")

    run_session(scenario)


def test_lines_past_the_limit_turn_a_document_away(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(server_module, "MAX_OPEN_LINES", 100)

    async def scenario(send: Callable[[Message], None], written: Collected) -> None:
        send(did_open("file:///empty-lines.rob", "\n" * 100))  # 101 lines, as LSP counts
        await settle()
        assert turned_away(written, "file:///empty-lines.rob", "100 lines in all")

    run_session(scenario)
