"""The language server as the studio's `/lsp` serves it: a session of lsp/server.py that
hears only of documents inside the folder the studio serves (spec/studio.md, "/lsp")."""

from __future__ import annotations

import json
from typing import Any
from urllib.parse import unquote, urlsplit

from .. import server as language_server
from .. import transports
from ..json_reading import read_json
from .files import Folder, Refused


class Confined:
    """A language server session that hears only of documents in the folder: a message
    about a document elsewhere is answered with an error (a request) or dropped."""

    def __init__(self, inner: language_server.Rl1Server, folder: Folder) -> None:
        self._inner = inner
        self._folder = folder
        self._writer: transports.Writer | None = None

    @property
    def exit_status(self) -> int | None:
        return self._inner.exit_status

    @property
    def initialized(self) -> bool:
        return self._inner.initialized

    def attach(self, writer: transports.Writer) -> None:
        self._writer = writer
        self._inner.attach(writer)

    def receive(self, body: bytes) -> None:
        try:
            message = read_json(body)
        except (ValueError, RecursionError):
            message = None  # the session answers what is no JSON
        if isinstance(message, dict) and (uri := _document_uri(message)) is not None \
                and not self._inside(uri):
            if "id" in message and self._writer is not None:
                self._writer.write(json.dumps({"jsonrpc": "2.0", "id": message["id"], "error": {
                    "code": -32602, "message": f"{uri} is outside {self._folder.root}, the "
                    "folder rl1c studio was started in: open documents inside it"}}).encode())
            return
        self._inner.receive(body)

    def end(self) -> None:
        self._inner.end()

    def _inside(self, uri: str) -> bool:
        parsed = urlsplit(uri)
        if parsed.scheme != "file" or parsed.netloc not in ("", "localhost"):
            return False
        try:
            self._folder.resolve(unquote(parsed.path))
        except Refused:
            return False
        return True


def new_session(folder: Folder) -> Confined:
    """A language server session of its own for one `/lsp` connection."""
    return Confined(language_server.create_server(), folder)


def _document_uri(message: dict[str, Any]) -> str | None:
    params = message.get("params")
    document = params.get("textDocument") if isinstance(params, dict) else None
    uri = document.get("uri") if isinstance(document, dict) else None
    return uri if isinstance(uri, str) else None
