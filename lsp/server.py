"""`rl1-lsp`: the RL/I language server. This module only wires LSP methods to the
feature modules; each handler finds the document and hands over.

Documents are kept by this server (document.py), not by pygls' workspace: the per-line
parse cache needs to see each change, and LSP's line breaks (LF, CRLF, CR) must be
honoured exactly.
"""

from __future__ import annotations

import asyncio
import functools
import json
import logging
import sys
from collections.abc import Callable
from importlib.metadata import version
from typing import Any, NamedTuple

import cattrs
import click
from cattrs.errors import ClassValidationError
from lsprotocol import types
from pygls.exceptions import (
    JsonRpcException,
    JsonRpcInvalidParams,
    JsonRpcInvalidRequest,
    JsonRpcMethodNotFound,
    JsonRpcParseError,
    JsonRpcServerNotInitialized,
)
from pygls.lsp.server import LanguageServer
from pygls.protocol import LanguageServerProtocol, default_converter

from rl1.compiler.cli.command import ToolCommand, command_line_status
from rl1.vm.config import excerpt, found

from . import (
    actions,
    checking,
    completion,
    formatting,
    hints,
    hover,
    navigation,
    test_files,
    tokens,
    transports,
)
from .document import MAX_ANALYSED_CHARACTERS, Document
from .framing import standard_streams
from .json_reading import read_json
from .positions import UTF16, Columns

log = logging.getLogger(__name__)

NAME = "rl1-lsp"

MAX_OPEN_DOCUMENTS = 500
MAX_OPEN_CHARACTERS = 8 * MAX_ANALYSED_CHARACTERS
MAX_OPEN_LINES = 1_000_000
MAX_ANALYSED_IN_ALL = MAX_ANALYSED_CHARACTERS
"""What one session holds: a document opened, or edited, past one of these limits is
dropped with a notice saying which. A document too large to analyse is kept in sync as
its text and some 200 bytes a line; analysis costs about 150 bytes a character
(bench/lsp_memory.py), so that a session holds at most about 300 MB of analysis and as
much again of text."""


class Weight(NamedTuple):
    """What documents count against a session's limits."""

    characters: int
    lines: int
    analysed: int  # the characters of those not too large to analyse

    @staticmethod
    def of(document: Document) -> Weight:
        return Weight(document.size, document.line_count,
                      0 if document.too_large else document.size)

    def plus(self, other: Weight, sign: int = 1) -> Weight:
        return Weight(*(mine + sign * theirs for mine, theirs in zip(self, other, strict=True)))


class _ParamsAnsweredInOneLine(logging.Filter):
    """pygls logs a traceback for each message whose params do not fit LSP; the
    session says what does not fit in one line (Rl1Protocol.structure_message)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return record.msg != "Unable to deserialize message\n%s"


class _RefusalsWithoutTraceback(logging.Filter):
    """pygls logs an error with a traceback for each request a handler refuses on
    purpose (a JsonRpcException: a rename off a label, an unknown command), which the
    client is answered with; the log says it in one line, at level info."""

    def filter(self, record: logging.LogRecord) -> bool:
        refused = record.exc_info[1] if record.exc_info else None
        if record.msg != 'Exception occurred for message "%s"' or not isinstance(
                refused, JsonRpcException):
            return True
        msg_id = record.args[0] if isinstance(record.args, tuple) and record.args else "?"
        record.msg, record.args = "refused request %s: %s", (msg_id, refused)
        record.exc_info, record.exc_text = None, None
        record.levelno, record.levelname = logging.INFO, "INFO"
        return logging.getLogger(record.name).isEnabledFor(logging.INFO)


logging.getLogger("pygls.protocol.json_rpc").addFilter(_ParamsAnsweredInOneLine())
logging.getLogger("pygls.protocol.json_rpc").addFilter(_RefusalsWithoutTraceback())


class Rl1Protocol(LanguageServerProtocol):
    """One session's end of JSON-RPC, fed each message's body by a transport
    (transports.py). pygls runs the requests (dispatch, cancellation, responses); this
    class answers what pygls leaves unanswered, which leaves the client waiting
    forever: malformed JSON (nested too deeply included), JSON that is no message,
    requests whose parameters do not fit the protocol, and requests out of the
    session's order (before `initialize`, after `shutdown`). It hands notifications to
    their handlers itself: pygls' dispatch of a notification costs five times a
    keystroke's edit, files a future that nothing removes (no upstream issue as of pygls
    2.1.1; the nearest are openlawlibrary/pygls#611 and #608), and its `exit` ends the
    process, where over TCP or a WebSocket it ends one session of many."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.initialize_received = False
        self.shutdown_received = False
        self.exit_status: int | None = None
        """Set by `exit`, as LSP gives it: the session is over."""

    # pygls caches these two with functools.lru_cache on the method, keyed by the protocol
    # too, which keeps the last 128 sessions alive after they end, each with its
    # connection and the last message the WebSocket library read (64 MiB each, found by
    # issue 23's campaign): looked up without the cache.
    def get_message_type(self, method: str) -> type[Any] | None:  # type: ignore[override]
        return types.METHOD_TO_TYPES.get(method, (None,))[0]

    def get_result_type(self, method: str) -> type[Any] | None:  # type: ignore[override]
        return types.METHOD_TO_TYPES.get(method, (None, None))[1]

    def receive(self, body: bytes) -> None:
        """Handle one message's body."""
        try:
            data = read_json(body)
        except RecursionError:
            self._refuse(None, JsonRpcParseError(
                "the message is nested too deeply to read: send a JSON-RPC message"))
            return
        except ValueError as error:  # JSONDecodeError and UnicodeDecodeError
            self._refuse(None, JsonRpcParseError(
                f"the message is not JSON in UTF-8 ({error}): send a JSON-RPC message"))
            return
        if not isinstance(data, dict) or "jsonrpc" not in data:  # JSON, but no message
            msg_id = data.get("id") if isinstance(data, dict) else None
            self._refuse(msg_id if isinstance(msg_id, int | str) else None, JsonRpcInvalidRequest(
                "not a JSON-RPC 2.0 message: send an object with \"jsonrpc\": \"2.0\""))
            return
        if "method" in data and not isinstance(method := data["method"], str):
            # pygls's structuring fails on it as an Internal Error, saying nothing
            msg_id = data.get("id")
            self._refuse(msg_id if isinstance(msg_id, int | str) else None,
                         JsonRpcInvalidRequest(f"`method` is {found(method, 'json')}: name "
                                               "the method with a string, as "
                                               "\"textDocument/hover\""))
            return
        try:
            message = self.structure_message(data)
        except JsonRpcException:  # answered, or said, by structure_message
            return
        try:
            if hasattr(message, "method") and not hasattr(message, "id"):
                self._notified(message.method, message)
            else:
                self.handle_message(message)
        except Exception:  # a bug in a handler: log it and go on serving
            log.exception("handling a message failed")

    def _notified(self, method: str, message: Any) -> None:
        if method == types.EXIT:
            self.exit_status = 0 if self.shutdown_received else 1
        elif method == types.CANCEL_REQUEST:
            self.handle_message(message)  # pygls cancels the request it runs
        elif not self.initialize_received or self.shutdown_received:
            log.warning("%s %s: dropped, as LSP asks", method,
                        "after shutdown" if self.shutdown_received else "before initialize")
        elif (handler := self.fm.features.get(method)) is not None:
            handler(message.params)
        else:  # such as $/setTrace and initialized, which need nothing done
            log.debug("%s: nothing to do", method)

    def handle_message(self, message: Any) -> None:
        method = getattr(message, "method", None)
        if method is not None and hasattr(message, "id"):  # a request
            if self.shutdown_received:
                self._refuse(message.id, JsonRpcInvalidRequest(
                    f"{excerpt(method)} after shutdown: the server only accepts exit now"))
                return
            if method == types.INITIALIZE and self.initialize_received:
                self._refuse(message.id, JsonRpcInvalidRequest(
                    "initialize was already received: send it once per session"))
                return
            if method != types.INITIALIZE and not self.initialize_received:
                self._refuse(message.id, JsonRpcServerNotInitialized(
                    f"{excerpt(method)} before initialize: send initialize first"))
                return
            if self._unknown(method):  # pygls would quote it whole, in its answer and log
                self._refuse(message.id, JsonRpcMethodNotFound(
                    f"`{excerpt(method)}` is no method rl1-lsp answers"))
                return
            self.initialize_received = True
            if method == types.SHUTDOWN:
                self.shutdown_received = True
        super().handle_message(message)

    def _unknown(self, method: object) -> bool:
        """Whether `method` is a string naming no method of LSP's or of this server's."""
        return isinstance(method, str) and self.get_message_type(method) is None \
            and method not in self.fm.features

    def structure_message(self, data: dict[str, Any]) -> Any:
        if self._unknown(data.get("method")):  # pygls' type needs params; LSP lets them go
            data = {"params": None, **data}
        try:
            return super().structure_message(data)
        except JsonRpcException as error:
            if isinstance(error.__cause__, ClassValidationError):
                what = "; ".join(cattrs.transform_error(error.__cause__)[:3])
                error = JsonRpcInvalidParams(
                    f"{data.get('method')}: {what}: send what the LSP specification gives")
            if "method" in data and isinstance(msg_id := data.get("id"), int | str):
                self._refuse(msg_id, error)
            else:
                log.warning("dropped a message that does not fit LSP: %s", error.message)
            raise error from None

    def _refuse(self, msg_id: object, error: JsonRpcException) -> None:
        """Answer a request (or, without an id, a message that could not be read) with
        an error: the writer is the transport's, which frames each message itself."""
        log.warning("%s", error.message)
        answer = {"jsonrpc": "2.0", "id": msg_id,
                  "error": {"code": error.code, "message": error.message}}
        if self.writer is not None:
            self.writer.write(json.dumps(answer).encode())


@functools.cache
def _converter() -> cattrs.Converter:
    """The one converter of every session: pygls registers its hooks on a converter when
    it makes one (default_converter) and never after, and reads messages with it on
    the event loop, so that it holds no session's state, only the functions it makes
    for each type, which the sessions then share (bench/lsp_sessions.py: one a session
    cost some 5 ms and 0.3 MiB)."""
    converter: cattrs.Converter = default_converter()  # type: ignore[no-untyped-call]
    return converter


class Rl1Server(LanguageServer):
    """One session: a client's documents and their analysis."""

    protocol: Rl1Protocol

    def __init__(self) -> None:
        super().__init__(NAME, version("rl1"), protocol_cls=Rl1Protocol,
                         converter_factory=_converter,
                         text_document_sync_kind=types.TextDocumentSyncKind.Incremental)
        self.documents: dict[str, Document] = {}
        self.held = Weight(0, 0, 0)  # the documents' in all
        self.columns = Columns(UTF16)
        self.snippets = False  # what the client's completion accepts
        self.markdown = False
        self.resolves_edits = False  # the client fills in a code action's edit on resolve
        self.checks = checking.DiagnosticsScheduler(
            self.text_document_publish_diagnostics, lambda: self.columns)
        self.token_history = tokens.TokenHistory()

    def document(self, uri: str) -> Document | None:
        """An open document the server analyses; None for unknown or huge ones, and
        for test files (TOML), which it only checks."""
        document = self.documents.get(uri)
        if document is None or document.too_large or test_files.is_test_file_uri(uri):
            return None
        return document

    def hold(self, document: Document) -> None:
        """Keep an opened document, or, beyond the limits, tell its client why not."""
        self.forget(document.uri)
        self.documents[document.uri] = document
        self.held = self.held.plus(Weight.of(document))
        if not self._turned_away(document):
            self.checks.schedule(document)

    def changed(self, document: Document, before: Weight) -> None:
        """A held document was edited: check it, or drop it if it grew past the limits."""
        self.held = self.held.plus(Weight.of(document)).plus(before, -1)
        if not self._turned_away(document):
            self.checks.schedule(document)

    def forget(self, uri: str) -> None:
        if (document := self.documents.pop(uri, None)) is not None:
            self.held = self.held.plus(Weight.of(document), -1)
        self.token_history.forget(uri)
        self.checks.cancel(uri)

    def _turned_away(self, document: Document) -> bool:
        """Whether holding `document` (already counted) goes past a limit: then it is
        dropped, and its client told which limit."""
        if len(self.documents) > MAX_OPEN_DOCUMENTS:
            limit = f"{MAX_OPEN_DOCUMENTS:,} open documents"
        elif self.held.characters > MAX_OPEN_CHARACTERS:
            limit = f"{MAX_OPEN_CHARACTERS:,} characters in all the documents open"
        elif self.held.lines > MAX_OPEN_LINES:
            limit = f"{MAX_OPEN_LINES:,} lines in all the documents open"
        elif self.held.analysed > MAX_ANALYSED_IN_ALL:
            limit = f"{MAX_ANALYSED_IN_ALL:,} characters in all the documents it analyses"
        else:
            return False
        log.warning("%s dropped: over the limit of %s", document.uri, limit)
        self.forget(document.uri)
        self.text_document_publish_diagnostics(types.PublishDiagnosticsParams(
            uri=document.uri, version=document.version,
            diagnostics=[checking.over_limits_notice(limit)]))
        return True

    # The session, as transports.py serves it ------------------------------------------

    @property
    def exit_status(self) -> int | None:
        return self.protocol.exit_status

    @property
    def initialized(self) -> bool:
        return self.protocol.initialize_received

    def attach(self, writer: transports.Writer) -> None:
        self.protocol.set_writer(writer, include_headers=False)  # the writer frames

    def receive(self, body: bytes) -> None:
        self.protocol.receive(body)

    def end(self) -> None:
        """The session is over: stop its checks, which would publish to no one, and let
        go of its documents and their analysis, most of what it holds, now: a session
        is a web of reference cycles, which only the garbage collector frees."""
        self.checks.stop()
        for uri in list(self.documents):
            self.forget(uri)


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
        action_caps = text_document.code_action if text_document else None
        resolving = action_caps.resolve_support if action_caps else None
        server.resolves_edits = bool(resolving and "edit" in resolving.properties)

    # Synchronisation ----------------------------------------------------------------

    @server.feature(types.TEXT_DOCUMENT_DID_OPEN)
    def did_open(params: types.DidOpenTextDocumentParams) -> None:
        item = params.text_document
        server.hold(Document(item.uri, item.text, item.version))

    @server.feature(types.TEXT_DOCUMENT_DID_CHANGE)
    def did_change(params: types.DidChangeTextDocumentParams) -> None:
        document = server.documents.get(params.text_document.uri)
        if document is None:
            log.warning("change to %s, which is not open: ignored", params.text_document.uri)
            return
        before = Weight.of(document)
        for change in params.content_changes:
            document.apply(change, server.columns)
        document.version = params.text_document.version
        server.changed(document, before)

    @server.feature(types.TEXT_DOCUMENT_DID_CLOSE)
    def did_close(params: types.DidCloseTextDocumentParams) -> None:
        server.forget(params.text_document.uri)
        server.checks.close(params.text_document.uri)

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
        code_action_kinds=[types.CodeActionKind.QuickFix, types.CodeActionKind.SourceFixAll],
        resolve_provider=True))
    def _(document: Document, params: types.CodeActionParams) -> list[types.CodeAction]:
        return actions.code_actions(document, server.checks.current(document), params.range,
                                    params.context.only, server.columns, server.resolves_edits)

    @server.feature(types.CODE_ACTION_RESOLVE)
    def resolve_code_action(action: types.CodeAction) -> types.CodeAction:
        return actions.resolve(action, server.document, server.columns)

    return server


@click.command(NAME, cls=ToolCommand)
@click.version_option(package_name="rl1", prog_name=NAME)
@click.option("--stdio", is_flag=True,
              help="talk LSP over standard input and output (the default)")
@click.option("--tcp", metavar="HOST:PORT", callback=lambda ctx, param, value: _host_port(value),
              help="listen on a TCP port instead: each connection is a session of its own, "
                   f"up to {transports.MAX_SESSIONS} at once")
@click.option("--ws", metavar="HOST:PORT", callback=lambda ctx, param, value: _host_port(value),
              help="listen for WebSocket connections instead (one LSP message a WebSocket "
                   "message; programs and pages served from this machine only), each a "
                   "session of its own; needs the websockets package: pip install 'rl1[ws]'")
@click.option("--log-level", type=click.Choice(["debug", "info", "warning", "error"]),
              default="warning", show_default=True, help="what to log on standard error")
def command(stdio: bool, tcp: tuple[str, int] | None, ws: tuple[str, int] | None,
            log_level: str) -> None:
    """The RL/I language server: diagnostics, hover, completion, navigation, renaming of
    labels, formatting and quick fixes for .rob files in any LSP editor."""
    if sum((stdio, tcp is not None, ws is not None)) > 1:
        raise click.UsageError("--stdio, --tcp and --ws exclude each other: choose one of "
                               "--stdio, --tcp and --ws")
    logging.basicConfig(level=log_level.upper(), format="rl1-lsp %(levelname)s: %(message)s")
    if tcp is None and ws is None:
        sys.exit(transports.serve_stdio(create_server(), *standard_streams()))
    if ws is not None:
        try:
            import websockets  # noqa: F401
        except ImportError:
            raise click.ClickException(
                "--ws needs the websockets package: pip install 'rl1[ws]'") from None
    serve = transports.serve_tcp if tcp is not None else transports.serve_websocket
    host, port = tcp or ws  # type: ignore[misc]
    try:
        asyncio.run(serve(create_server, host, port))
    except OSError as error:
        raise click.ClickException(
            f"cannot listen on {host}:{port}: {error.strerror or error}. Choose another "
            "port, or stop the program that listens on it") from None
    except KeyboardInterrupt:
        sys.exit(130)


def main(argv: list[str] | None = None) -> None:
    """The `rl1-lsp` command line (default: the process's arguments); serves until the
    client leaves, then exits. Help, the version and a malformed command line exit too,
    the last as rl1c's do: `rl1-lsp: error: ...`, status 2."""
    sys.exit(command_line_status(  # the name, also under `python -m rl1.lsp`
        lambda: command.main(argv, prog_name=NAME, standalone_mode=False), NAME))


def _host_port(text: str | None) -> tuple[str, int] | None:
    """The value of --tcp: `HOST:PORT`."""
    if text is None:
        return None
    host, _, port = text.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise click.BadParameter(f"expected HOST:PORT such as 127.0.0.1:2087, got {text!r}")
    return host, int(port)
