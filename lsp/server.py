"""`rl1-lsp`: the RL/I language server. This module only wires LSP methods to the
feature modules; each handler finds the document and hands over.

Documents are kept by this server (document.py), not by pygls' workspace: the per-line
parse cache needs to see each change, and LSP's line breaks (LF, CRLF, CR) must be
honoured exactly.
"""

from __future__ import annotations

import asyncio
import json
import logging
import sys
from collections.abc import Callable, Generator
from functools import partial
from importlib.metadata import version
from threading import Event
from typing import Any, BinaryIO

import click
from lsprotocol import types
from pygls.exceptions import (
    JsonRpcException,
    JsonRpcInvalidRequest,
    JsonRpcParseError,
    JsonRpcServerNotInitialized,
)
from pygls.io_ import StdoutWriter
from pygls.lsp.server import LanguageServer
from pygls.protocol import LanguageServerProtocol
from pygls.protocol.language_server import lsp_method

from . import actions, checking, completion, formatting, framing, hints, hover, navigation, tokens
from .document import Document
from .positions import UTF16, Columns

NAME = "rl1-lsp"


class Rl1Protocol(LanguageServerProtocol):
    """Passes document synchronisation straight to the server's handlers, leaving
    pygls' own copy of the documents out, and answers what pygls leaves unanswered,
    which leaves the client waiting forever: requests whose parameters do not fit the
    protocol, malformed JSON, JSON that is no message, and requests out of the
    session's order (before `initialize`, after `shutdown`)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.initialize_received = False  # before pygls' __init__, which reads `ready`
        super().__init__(*args, **kwargs)

    def receive(self, body: bytes) -> None:
        """Handle one message's body, as read by framing.read_messages."""
        try:
            data = json.loads(body)
        except ValueError as error:  # JSONDecodeError and UnicodeDecodeError
            self._refuse(None, JsonRpcParseError(
                f"the message is not JSON in UTF-8 ({error}): send a JSON-RPC message"))
            return
        if not isinstance(data, dict) or "jsonrpc" not in data:  # JSON, but no message
            msg_id = data.get("id") if isinstance(data, dict) else None
            self._refuse(msg_id if isinstance(msg_id, int | str) else None, JsonRpcInvalidRequest(
                "not a JSON-RPC 2.0 message: send an object with \"jsonrpc\": \"2.0\""))
            return
        try:
            message = self.structure_message(data)
        except JsonRpcException as error:  # answered by structure_message if a request
            logging.warning("a message that does not fit LSP: %s", error)
            return
        try:
            if type(message) is types.DidChangeTextDocumentNotification and self.ready:
                # The one message a burst repeats a thousand times: pygls' dispatch
                # costs five times the edit itself.
                self.fm.features[types.TEXT_DOCUMENT_DID_CHANGE](message.params)
            else:
                self.handle_message(message)
        except Exception as error:  # as pygls' reader does: log, tell the client, go on
            logging.exception("handling a message failed")
            self._server._report_server_error(error, JsonRpcException)

    @property
    def ready(self) -> bool:
        """Between `initialize` and `shutdown`: notifications are handled."""
        return self.initialize_received and not self._shutdown

    def handle_message(self, message: Any) -> None:
        method = getattr(message, "method", None)
        if method is not None and hasattr(message, "id"):  # a request
            if self._shutdown:
                self._refuse(message.id, JsonRpcInvalidRequest(
                    f"{method} after shutdown: the server only accepts exit now"))
                return
            if method == types.INITIALIZE and self.initialize_received:
                self._refuse(message.id, JsonRpcInvalidRequest(
                    "initialize was already received: send it once per session"))
                return
            if method != types.INITIALIZE and not self.initialize_received:
                self._refuse(message.id, JsonRpcServerNotInitialized(
                    f"{method} before initialize: send initialize first"))
                return
            self.initialize_received = True
        elif method not in (None, types.EXIT) and not self.initialize_received:
            logging.warning("%s before initialize: dropped, as LSP asks", method)
            return
        super().handle_message(message)

    def _handle_notification(self, method_name: str, params: Any) -> None:
        # pygls files the future of a notification's handler under a fresh id that no
        # response ever removes: one entry per didChange, megabytes per burst of edits.
        outstanding = set(self._request_futures)
        super()._handle_notification(method_name, params)
        for msg_id in self._request_futures.keys() - outstanding:
            future = self._request_futures[msg_id]
            if future.done():
                del self._request_futures[msg_id]
            else:
                future.add_done_callback(partial(self._forget_future, msg_id))

    def _forget_future(self, msg_id: int | str, _: object) -> None:
        self._request_futures.pop(msg_id, None)

    def _refuse(self, msg_id: int | str | None, error: JsonRpcException) -> None:
        logging.warning("%s", error.message)
        self._send_response(msg_id, error=error.to_response_error())  # type: ignore[arg-type]

    def structure_message(self, data: dict[str, Any]) -> Any:
        try:
            return super().structure_message(data)
        except JsonRpcException as error:
            if "id" in data and "method" in data:
                self._send_response(data["id"], error=error.to_response_error())
            raise

    def _user(self, method: str, params: object) -> Generator[Any, Any, None]:
        if (handler := self.fm.features.get(method)) is not None:
            yield handler, (params,), None

    @lsp_method(types.TEXT_DOCUMENT_DID_OPEN)
    def lsp_text_document__did_open(
            self, params: types.DidOpenTextDocumentParams) -> Generator[Any, Any, None]:
        yield from self._user(types.TEXT_DOCUMENT_DID_OPEN, params)

    @lsp_method(types.TEXT_DOCUMENT_DID_CHANGE)
    def lsp_text_document__did_change(
            self, params: types.DidChangeTextDocumentParams) -> Generator[Any, Any, None]:
        yield from self._user(types.TEXT_DOCUMENT_DID_CHANGE, params)

    @lsp_method(types.TEXT_DOCUMENT_DID_CLOSE)
    def lsp_text_document__did_close(
            self, params: types.DidCloseTextDocumentParams) -> Generator[Any, Any, None]:
        yield from self._user(types.TEXT_DOCUMENT_DID_CLOSE, params)


class Rl1Server(LanguageServer):
    def __init__(self) -> None:
        super().__init__(NAME, version("rl1"), protocol_cls=Rl1Protocol,
                         text_document_sync_kind=types.TextDocumentSyncKind.Incremental)
        self.documents: dict[str, Document] = {}
        self.columns = Columns(UTF16)
        self.snippets = False  # what the client's completion accepts
        self.markdown = False
        self.checks = checking.DiagnosticsScheduler(
            self.text_document_publish_diagnostics, lambda: self.columns)
        self.token_history = tokens.TokenHistory()

    def start_io(self, stdin: BinaryIO | None = None, stdout: BinaryIO | None = None) -> None:
        """Serve over standard input and output, with framing.py's reader in place of
        pygls' (the rest as pygls' own start_io). LSP's `exit` ends the process with
        the status LSP gives it."""
        self._stop_event = Event()
        self.protocol.set_writer(StdoutWriter(stdout or sys.stdout.buffer))
        fd = (stdin or sys.stdin.buffer).fileno()
        assert isinstance(self.protocol, Rl1Protocol)
        try:
            asyncio.run(framing.read_messages(fd, self.protocol.receive, self._stop_event))
        except BrokenPipeError:
            logging.error("the client closed its end of the connection: exiting")
        finally:
            self.shutdown()  # type: ignore[no-untyped-call]  # pygls has no hints here

    def document(self, uri: str) -> Document | None:
        """An open document the server analyses; None for unknown or huge ones."""
        document = self.documents.get(uri)
        return None if document is None or document.too_large else document


def create_server() -> Rl1Server:
    server = Rl1Server()

    @server.feature(types.INITIALIZE)
    def initialize(params: types.InitializeParams) -> None:
        encoding = server.workspace.position_encoding or UTF16
        if isinstance(encoding, types.PositionEncodingKind):
            encoding = encoding.value
        server.columns = Columns(encoding)
        text_document = params.capabilities.text_document
        completion_caps = text_document.completion if text_document else None
        item = completion_caps.completion_item if completion_caps else None
        server.snippets = bool(item and item.snippet_support)
        formats = (item.documentation_format if item else None) or []
        server.markdown = types.MarkupKind.Markdown in formats

    # Synchronisation ----------------------------------------------------------------

    @server.feature(types.TEXT_DOCUMENT_DID_OPEN)
    def did_open(params: types.DidOpenTextDocumentParams) -> None:
        item = params.text_document
        document = Document(item.uri, item.text, item.version)
        server.documents[item.uri] = document
        server.checks.schedule(document)

    @server.feature(types.TEXT_DOCUMENT_DID_CHANGE)
    def did_change(params: types.DidChangeTextDocumentParams) -> None:
        document = server.documents.get(params.text_document.uri)
        if document is None:
            logging.warning("change to %s, which is not open: ignored", params.text_document.uri)
            return
        for change in params.content_changes:
            document.apply(change, server.columns)
        document.version = params.text_document.version
        server.checks.schedule(document)

    @server.feature(types.TEXT_DOCUMENT_DID_CLOSE)
    def did_close(params: types.DidCloseTextDocumentParams) -> None:
        uri = params.text_document.uri
        server.documents.pop(uri, None)
        server.token_history.forget(uri)
        server.checks.close(uri)

    # Everything else reads one document -----------------------------------------------

    def reads(method: str, empty: Any = None, options: Any = None) -> Callable[
            [Callable[[Document, Any], Any]], None]:
        """Registers a handler of `method` called with the open document and the params;
        the answer is `empty` for a document that is not open or too large."""
        def register(handler: Callable[[Document, Any], Any]) -> None:
            @server.feature(method, options)
            def run(params: Any) -> Any:
                document = server.document(params.text_document.uri)
                return empty if document is None else handler(document, params)
        return register

    @reads(types.TEXT_DOCUMENT_HOVER)
    def _(document: Document, params: types.HoverParams) -> types.Hover | None:
        return hover.hover(document, params.position, server.columns)

    @reads(types.TEXT_DOCUMENT_COMPLETION, [],
           types.CompletionOptions(trigger_characters=completion.TRIGGER_CHARACTERS))
    def _(document: Document, params: types.CompletionParams) -> list[types.CompletionItem]:
        return completion.complete(document, params.position, server.columns,
                                   server.snippets, server.markdown)

    @reads(types.TEXT_DOCUMENT_SIGNATURE_HELP, None,
           types.SignatureHelpOptions(trigger_characters=completion.SIGNATURE_TRIGGERS))
    def _(document: Document, params: types.SignatureHelpParams) -> types.SignatureHelp | None:
        return completion.signature_help(document, params.position, server.columns)

    @reads(types.TEXT_DOCUMENT_INLAY_HINT, [])
    def _(document: Document, params: types.InlayHintParams) -> list[types.InlayHint]:
        return hints.inlay_hints(document, params.range, server.columns)

    @reads(types.TEXT_DOCUMENT_SEMANTIC_TOKENS_FULL, None, tokens.LEGEND)
    def _(document: Document, params: types.SemanticTokensParams) -> types.SemanticTokens:
        return server.token_history.full(document, server.columns)

    @reads(types.TEXT_DOCUMENT_SEMANTIC_TOKENS_FULL_DELTA, None, tokens.LEGEND)
    def _(document: Document, params: types.SemanticTokensDeltaParams
          ) -> types.SemanticTokens | types.SemanticTokensDelta:
        return server.token_history.delta(document, server.columns, params.previous_result_id)

    @reads(types.TEXT_DOCUMENT_DEFINITION)
    def _(document: Document, params: types.DefinitionParams) -> list[types.Location] | None:
        return navigation.definition(document, params.position, server.columns)

    @reads(types.TEXT_DOCUMENT_REFERENCES, [])
    def _(document: Document, params: types.ReferenceParams) -> list[types.Location]:
        return navigation.references(document, params.position, server.columns,
                                     params.context.include_declaration)

    @reads(types.TEXT_DOCUMENT_DOCUMENT_HIGHLIGHT, [])
    def _(document: Document, params: types.DocumentHighlightParams
          ) -> list[types.DocumentHighlight]:
        return navigation.highlights(document, params.position, server.columns)

    @reads(types.TEXT_DOCUMENT_PREPARE_RENAME)
    def _(document: Document, params: types.PrepareRenameParams) -> types.PrepareRenameResult:
        return navigation.prepare_rename(document, params.position, server.columns)

    @reads(types.TEXT_DOCUMENT_RENAME)
    def _(document: Document, params: types.RenameParams) -> types.WorkspaceEdit:
        return navigation.rename(document, params.position, server.columns, params.new_name)

    @reads(types.TEXT_DOCUMENT_DOCUMENT_SYMBOL, [])
    def _(document: Document, params: types.DocumentSymbolParams) -> list[types.DocumentSymbol]:
        return navigation.symbols(document, server.columns)

    @reads(types.TEXT_DOCUMENT_FOLDING_RANGE, [])
    def _(document: Document, params: types.FoldingRangeParams) -> list[types.FoldingRange]:
        return navigation.folding_ranges(document)

    @reads(types.TEXT_DOCUMENT_FORMATTING, [])
    def _(document: Document, params: types.DocumentFormattingParams) -> list[types.TextEdit]:
        return formatting.format_document(document, server.columns)

    @reads(types.TEXT_DOCUMENT_RANGE_FORMATTING, [])
    def _(document: Document, params: types.DocumentRangeFormattingParams
          ) -> list[types.TextEdit]:
        return formatting.format_range(document, params.range, server.columns)

    @reads(types.TEXT_DOCUMENT_CODE_ACTION, [], types.CodeActionOptions(
        code_action_kinds=[types.CodeActionKind.QuickFix, types.CodeActionKind.SourceFixAll]))
    def _(document: Document, params: types.CodeActionParams) -> list[types.CodeAction]:
        return actions.code_actions(document, server.checks.current(document), params.range,
                                    params.context.only, server.columns)

    return server


@click.command(NAME, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="rl1", prog_name=NAME)
@click.option("--stdio", is_flag=True,
              help="talk LSP over standard input and output (the default)")
@click.option("--tcp", metavar="HOST:PORT", callback=lambda ctx, param, value: _host_port(value),
              help="listen for one client on a TCP port instead")
@click.option("--log-level", type=click.Choice(["debug", "info", "warning", "error"]),
              default="warning", show_default=True, help="what to log on standard error")
def command(stdio: bool, tcp: tuple[str, int] | None, log_level: str) -> None:
    """The RL/I language server: diagnostics, hover, completion, navigation, renaming of
    labels, formatting and quick fixes for .rob files in any LSP editor."""
    if tcp is not None and stdio:
        raise click.UsageError("--stdio and --tcp exclude each other: choose one of --stdio "
                               "and --tcp")
    logging.basicConfig(level=log_level.upper(), format="rl1-lsp %(levelname)s: %(message)s")
    server = create_server()
    if tcp is None:
        server.start_io()
    else:
        server.start_tcp(*tcp)


def main(argv: list[str] | None = None) -> None:
    """The `rl1-lsp` command line (default: the process's arguments); serves until the
    client leaves, then exits. Help, the version and a malformed command line exit too."""
    command.main(argv, prog_name=NAME)  # the name, also under `python -m rl1.lsp`


def _host_port(text: str | None) -> tuple[str, int] | None:
    """The value of --tcp: `HOST:PORT`."""
    if text is None:
        return None
    host, _, port = text.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise click.BadParameter(f"expected HOST:PORT such as 127.0.0.1:2087, got {text!r}")
    return host, int(port)
