"""The studio's `/lsp` (spec/studio.md): the language server over the WebSocket as
`rl1-lsp --ws` serves it, a session a connection, hearing only of documents inside the
folder the studio serves."""

from __future__ import annotations

import contextlib
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from served import TIMEOUT, Served, sample_folder, serving
from websockets.sync.client import ClientConnection, connect


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return sample_folder(tmp_path_factory.mktemp("robots")).resolve()


@pytest.fixture(scope="module")
def served(folder: Path) -> Iterator[Served]:
    with serving(folder) as server:
        yield server


@contextlib.contextmanager
def language_server(served: Served) -> Iterator[ClientConnection]:
    with connect(served.url("/lsp", scheme="ws"), open_timeout=TIMEOUT) as client:
        send(client, {"id": 1, "method": "initialize", "params": {
            "processId": None, "rootUri": None, "capabilities": {}}})
        assert "capabilities" in until(client, lambda message: message.get("id") == 1)["result"]
        send(client, {"method": "initialized", "params": {}})
        yield client


def send(client: ClientConnection, message: dict[str, Any]) -> None:
    client.send(json.dumps({"jsonrpc": "2.0", **message}))


def until(client: ClientConnection, wanted: Any) -> dict[str, Any]:
    while True:
        message: dict[str, Any] = json.loads(client.recv(timeout=TIMEOUT))
        if wanted(message):
            return message


def open_document(client: ClientConnection, uri: str, text: str) -> None:
    send(client, {"method": "textDocument/didOpen", "params": {"textDocument": {
        "uri": uri, "languageId": "rl1", "version": 1, "text": text}}})


def test_a_document_in_the_folder_gets_its_diagnostics(served: Served, folder: Path) -> None:
    uri = (folder / "sample.rob").as_uri()
    with language_server(served) as client:
        open_document(client, uri, "A=(FOO)\n(END)\n")
        published = until(client, lambda message: message.get("method")
                          == "textDocument/publishDiagnostics")
    assert published["params"]["uri"] == uri
    assert [d["code"] for d in published["params"]["diagnostics"]] == ["E0501"]


@pytest.mark.parametrize("where", ["file:///etc/robot.rob", "file://elsewhere{folder}/a.rob",
                                   "file://{folder}/../outside.rob", "untitled:robot.rob"])
def test_a_document_elsewhere_is_refused(served: Served, folder: Path, where: str) -> None:
    uri = where.format(folder=folder)
    inside = (folder / "sample.rob").as_uri()
    with language_server(served) as client:
        open_document(client, uri, "A=(FOO)\n")
        send(client, {"id": 2, "method": "textDocument/hover", "params": {
            "textDocument": {"uri": uri}, "position": {"line": 0, "character": 3}}})
        answer = until(client, lambda message: message.get("id") == 2)
        assert answer["error"]["code"] == -32602
        assert "outside" in answer["error"]["message"]
        # The session goes on, and published nothing of the refused document.
        open_document(client, inside, "(END)\n")
        published = until(client, lambda message: message.get("method")
                          == "textDocument/publishDiagnostics")
        assert published["params"]["uri"] == inside
