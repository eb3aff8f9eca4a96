"""The server never crashes or hangs: arbitrary and binary content, a 10 MB document,
edits outside the document, unknown documents, malformed and cancelled requests, and a
feature that fails."""

from __future__ import annotations

import asyncio
import sys
from collections.abc import AsyncIterator, Awaitable, Callable
from concurrent.futures import Future
from pathlib import Path

import pytest
import pytest_lsp
from conftest import TIMEOUT, Client, initialize_params, make_client
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pytest_lsp import ClientServerConfig

from rl1.lsp.document import MAX_ANALYSED_LINE

pytestmark = pytest.mark.asyncio(loop_scope="module")

UNKNOWN = types.TextDocumentIdentifier("file:///never/opened.rob")


async def still_serving(client: Client) -> None:
    """The server answers a hover on a fresh document correctly."""
    uri, _ = await client.opened("(MOV 3,3)\n")
    result = await client.text_document_hover_async(types.HoverParams(
        types.TextDocumentIdentifier(uri), types.Position(0, 2)))
    assert result is not None


@settings(max_examples=20, deadline=None, suppress_health_check=list(HealthCheck))
@given(text=st.text(max_size=200), line=st.integers(0, 10), character=st.integers(0, 300))
async def test_arbitrary_text_gets_diagnostics_and_answers(
        client: Client, text: str, line: int, character: int) -> None:
    uri, _ = await client.opened(text)
    position = types.Position(line, character)
    identifier = types.TextDocumentIdentifier(uri)
    await client.text_document_hover_async(types.HoverParams(identifier, position))
    await client.text_document_completion_async(types.CompletionParams(identifier, position))
    await client.text_document_semantic_tokens_full_async(types.SemanticTokensParams(identifier))
    await client.text_document_formatting_async(types.DocumentFormattingParams(
        identifier, types.FormattingOptions(tab_size=4, insert_spaces=True)))


async def test_binary_content(client: Client) -> None:
    binary = bytes(range(256)).decode("latin-1") * 4 + "\x00\ufffe\U0010ffff\ud800"
    uri, diagnostics = await client.opened(binary)
    assert any(d.code == "E0102" for d in diagnostics)
    await client.text_document_document_symbol_async(
        types.DocumentSymbolParams(types.TextDocumentIdentifier(uri)))
    await still_serving(client)


async def test_a_ten_megabyte_document_is_refused_clearly_and_quickly(client: Client) -> None:
    huge = "A=B+1; (MOV 3,3) ' padding\n" * 400_000
    assert len(huge) > 10_000_000
    async with asyncio.timeout(TIMEOUT):
        uri, diagnostics = await client.opened(huge)
    (notice,) = diagnostics
    assert "rl1c check" in notice.message and "characters" in notice.message
    hover = await client.text_document_hover_async(types.HoverParams(
        types.TextDocumentIdentifier(uri), types.Position(5, 1)))
    assert hover is None
    # shrinking it below the limit brings the analysis back
    client.change(uri, 2, ((10, 0, 400_000, 0), ""))
    assert await client.diagnostics_of(uri, 2) is not None
    hover = await client.text_document_hover_async(types.HoverParams(
        types.TextDocumentIdentifier(uri), types.Position(5, 1)))
    assert hover is not None


async def test_a_long_line_with_a_japanese_comment_is_not_quadratic(client: Client) -> None:
    text = "A=1;" * 4_990 + "'日本語😀\n"  # just within MAX_ANALYSED_LINE
    assert len(text) <= MAX_ANALYSED_LINE
    async with asyncio.timeout(TIMEOUT):
        uri, _ = await client.opened(text)
        tokens = await client.text_document_semantic_tokens_full_async(
            types.SemanticTokensParams(types.TextDocumentIdentifier(uri)))
    assert tokens is not None
    # the comment: 2 after the last `1` (column 19,958), 6 UTF-16 units long
    assert list(tokens.data[-5:]) == [0, 2, 6, 7, 0]


async def test_a_megabyte_line_is_refused_clearly_and_the_fix_brings_analysis_back(
        client: Client) -> None:
    text = "A=1\n" + "B=2;" * 250_000 + "\n(END)\n"
    async with asyncio.timeout(TIMEOUT):
        uri, diagnostics = await client.opened(text)
    (notice,) = diagnostics
    assert "line 2 " in notice.message and "1,000,000 characters" in notice.message
    assert "rl1c check" in notice.message
    client.change(uri, 2, ((1, 0, 1, 1_000_000), "B=2"))
    async with asyncio.timeout(TIMEOUT):
        fixed = await client.diagnostics_of(uri, 2)
    assert not any("characters" in d.message for d in fixed)
    hover = await client.text_document_hover_async(types.HoverParams(
        types.TextDocumentIdentifier(uri), types.Position(1, 0)))
    assert hover is not None


async def test_edits_outside_the_document_are_clamped(client: Client) -> None:
    uri, _ = await client.opened("A=1\n")
    client.change(uri, 2, ((50, 7, 90, 3), "(MOV"))  # past the end: appended
    diagnostics = await client.diagnostics_of(uri, 2)
    assert [(d.code, d.range.start.line) for d in diagnostics if d.code == "E0101"] == [
        ("E0101", 1)]
    client.change(uri, 3, ((1, 0, 0, 0), ""))  # end before start: taken in order
    client.change(uri, 4, ((0, 999, 0, 999), " 2,2)"))  # past the end of a line
    diagnostics = await client.diagnostics_of(uri, 4)  # the text is now "(MOV 2,2)"
    assert not [d for d in diagnostics if str(d.code).startswith("E01")]
    symbols = await client.text_document_semantic_tokens_full_async(
        types.SemanticTokensParams(types.TextDocumentIdentifier(uri)))
    assert symbols is not None and list(symbols.data[:3]) == [0, 1, 3]  # `MOV` on line 0


async def test_requests_for_unknown_documents_answer_empty(client: Client) -> None:
    position = types.Position(0, 0)
    assert await client.text_document_hover_async(types.HoverParams(UNKNOWN, position)) is None
    assert await client.text_document_definition_async(
        types.DefinitionParams(UNKNOWN, position)) is None
    assert await client.text_document_completion_async(
        types.CompletionParams(UNKNOWN, position)) == []
    assert await client.text_document_document_symbol_async(
        types.DocumentSymbolParams(UNKNOWN)) == []
    assert await client.text_document_semantic_tokens_full_async(
        types.SemanticTokensParams(UNKNOWN)) is None
    client.change(UNKNOWN.uri, 2, ((0, 0, 0, 0), "A"))  # ignored, not fatal
    client.text_document_did_close(types.DidCloseTextDocumentParams(UNKNOWN))
    await still_serving(client)


def send_raw(client: Client, message: dict[str, object]) -> asyncio.Future[object]:
    """Send a message as given, bypassing the client's typed requests; the answer to a
    request comes back through the returned future."""
    answer: Future[object] = Future()
    if "id" in message:
        client.protocol._request_futures[str(message["id"])] = answer
    client.protocol._send_data({"jsonrpc": "2.0", **message})
    return asyncio.wrap_future(answer)


async def test_malformed_params_get_an_error_response(client: Client) -> None:
    with pytest.raises(JsonRpcException, match=r"expected int @ \$\.params\.position\.line"):
        await send_raw(client, {"id": "bad-1", "method": types.TEXT_DOCUMENT_HOVER,
                                "params": {"textDocument": {"uri": 42}, "position": "here"}})
    send_raw(client, {"method": types.TEXT_DOCUMENT_DID_CHANGE, "params": {"textDocument": 1}})
    await still_serving(client)


async def test_cancelled_requests_are_answered_or_cancelled(client: Client) -> None:
    uri, _ = await client.opened("A=1\n" * 2000)
    identifier = types.TextDocumentIdentifier(uri)
    futures = []
    for index in range(20):
        msg_id = f"cancel-me-{index}"
        futures.append(client.protocol.send_request_async(  # type: ignore[no-untyped-call]
            types.TEXT_DOCUMENT_SEMANTIC_TOKENS_FULL, types.SemanticTokensParams(identifier),
            msg_id=msg_id))
        client.protocol.notify(types.CANCEL_REQUEST, types.CancelParams(id=msg_id))
    for future in futures:
        try:
            await future
        except JsonRpcException as error:
            assert "cancel" in error.message.lower()
    await still_serving(client)


# A server with a failing feature ---------------------------------------------------------

FAULTY = [sys.executable, str(Path(__file__).with_name("faulty_server.py"))]


@pytest_lsp.fixture(  # type: ignore[untyped-decorator]
    scope="module", config=ClientServerConfig(server_command=FAULTY, client_factory=make_client))
async def faulty(lsp_client: Client) -> AsyncIterator[None]:
    await lsp_client.initialize_session(initialize_params())
    yield
    await lsp_client.shutdown_session()


async def test_failing_features_answer_errors_and_the_server_goes_on(faulty: Client) -> None:
    uri, diagnostics = await faulty.opened(":10 (MOV 3,3); #10\nA=(\n")
    # the checker's failure is reported, and the syntax error is still shown
    assert "checker failed" in diagnostics[0].message
    assert [d.code for d in diagnostics[1:]] == ["E0101"]
    identifier = types.TextDocumentIdentifier(uri)
    position = types.Position(0, 16)
    failing: list[Callable[[], Awaitable[object]]] = [
        lambda: faulty.text_document_hover_async(types.HoverParams(identifier, position)),
        lambda: faulty.text_document_completion_async(
            types.CompletionParams(identifier, position)),
        lambda: faulty.text_document_definition_async(
            types.DefinitionParams(identifier, position)),
        lambda: faulty.text_document_document_symbol_async(
            types.DocumentSymbolParams(identifier)),
        lambda: faulty.text_document_semantic_tokens_full_async(
            types.SemanticTokensParams(identifier)),
    ]
    for request in failing * 2:
        with pytest.raises(JsonRpcException, match="planted failure"):
            await request()
    references = await faulty.text_document_references_async(types.ReferenceParams(
        context=types.ReferenceContext(include_declaration=True), text_document=identifier,
        position=position))
    starts = [r.range.start for r in references or []]
    assert starts == [types.Position(0, 0), types.Position(0, 15)]
    faulty.change(uri, 2, ((1, 2, 1, 3), "1"))
    assert [d.code for d in await faulty.diagnostics_of(uri, 2)] == [None]


async def test_a_failed_checker_does_not_make_allow_comments_look_unused(faulty: Client) -> None:
    # W0701 comes from the whole-program rules, which failed: its comment is not W0107.
    _, diagnostics = await faulty.opened("(MOV 3,3); (END) ' rl1: allow W0701\n")
    assert "checker failed" in diagnostics[0].message
    assert diagnostics[1:] == []
