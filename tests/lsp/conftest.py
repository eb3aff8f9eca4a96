"""The language server under test: `python -m rl1.lsp` in a subprocess over stdio, one
per test module, driven by pytest-lsp's client."""

from __future__ import annotations

import asyncio
import copy
import itertools
import sys
from collections.abc import AsyncIterator
from typing import Any

import pytest_lsp
from lsprotocol import types
from pygls.protocol import default_converter
from pytest_lsp import ClientServerConfig, LanguageClient
from pytest_lsp.client import DEFAULT_CLIENT_FEATURES, register_lsp_features

SERVER = [sys.executable, "-m", "rl1.lsp"]
TIMEOUT = 30.0

CAPABILITIES = types.ClientCapabilities(
    text_document=types.TextDocumentClientCapabilities(
        completion=types.CompletionClientCapabilities(
            completion_item=types.ClientCompletionItemOptions(
                snippet_support=True, documentation_format=[types.MarkupKind.Markdown])),
        rename=types.RenameClientCapabilities(prepare_support=True),
        semantic_tokens=types.SemanticTokensClientCapabilities(
            requests=types.ClientSemanticTokensRequestOptions(
                full=types.ClientSemanticTokensRequestFullDelta(delta=True)),
            token_types=[], token_modifiers=[], formats=[types.TokenFormat.Relative]),
    ),
)


class Client(LanguageClient):
    """pytest-lsp's client, also keeping every publishDiagnostics in order."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.published: list[types.PublishDiagnosticsParams] = []
        self._uris = itertools.count(1)

    def new_uri(self) -> str:
        return f"file:///work/test{next(self._uris)}.rob"

    def open(self, text: str, uri: str | None = None, version: int = 1) -> str:
        uri = uri or self.new_uri()
        self.text_document_did_open(types.DidOpenTextDocumentParams(
            types.TextDocumentItem(uri=uri, language_id="rl1", version=version, text=text)))
        return uri

    def change(self, uri: str, version: int,
               *changes: tuple[tuple[int, int, int, int], str]) -> None:
        """Send incremental changes, each ((line, char, end_line, end_char), text)."""
        self.text_document_did_change(types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=uri, version=version),
            content_changes=[
                types.TextDocumentContentChangePartial(
                    range=types.Range(types.Position(a, b), types.Position(c, d)), text=text)
                for (a, b, c, d), text in changes
            ],
        ))

    async def diagnostics_of(self, uri: str, version: int) -> list[types.Diagnostic]:
        """The diagnostics published for this version of the document."""
        async with asyncio.timeout(TIMEOUT):
            while True:
                for params in self.published:
                    if params.uri == uri and params.version == version:
                        return list(params.diagnostics)
                await asyncio.sleep(0.005)

    async def opened(self, text: str, uri: str | None = None) -> tuple[str, list[types.Diagnostic]]:
        """Open a document and wait for its first diagnostics."""
        uri = self.open(text, uri)
        return uri, await self.diagnostics_of(uri, 1)


def _record(client: Client, params: types.PublishDiagnosticsParams) -> None:
    client.published.append(params)
    client.diagnostics[params.uri] = params.diagnostics


def make_client() -> Client:
    client = Client(converter_factory=default_converter)
    features = {**DEFAULT_CLIENT_FEATURES, types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS: _record}
    register_lsp_features(client, features)
    return client


def initialize_params(capabilities: types.ClientCapabilities = CAPABILITIES
                      ) -> types.InitializeParams:
    return types.InitializeParams(capabilities=copy.deepcopy(capabilities),
                                  root_uri="file:///work")


@pytest_lsp.fixture(  # type: ignore[untyped-decorator]
    scope="module", config=ClientServerConfig(server_command=SERVER, client_factory=make_client))
async def client(lsp_client: Client) -> AsyncIterator[None]:
    await lsp_client.initialize_session(initialize_params())
    yield
    await lsp_client.shutdown_session()


def position_of(text: str, needle: str, offset: int = 0) -> types.Position:
    """The position of the first `needle` in `text` (plus `offset` characters), in
    UTF-16 units as the test client counts."""
    index = text.index(needle) + offset
    line = text.count("\n", 0, index)
    start = text.rfind("\n", 0, index) + 1
    return types.Position(line, len(text[start:index].encode("utf-16-le")) // 2)
