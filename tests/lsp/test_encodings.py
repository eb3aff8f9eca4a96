"""Position encodings: the server takes UTF-8 or UTF-32 when the client offers it, and
counts every column in it; UTF-16 otherwise. Japanese comments never shift columns."""

from __future__ import annotations

import pytest
from conftest import SERVER, Client, initialize_params, make_client
from lsprotocol import types
from pytest_lsp import ClientServerConfig

pytestmark = pytest.mark.asyncio(loop_scope="function")

# The E0102 error is on the emoji: code-point column 4, one code point, two UTF-16
# units, four UTF-8 bytes.
TEXT = "'日本語のコメント\nA=1;😀;B=2 'ｺﾒﾝﾄ\n"
EMOJI_END = {"utf-8": 8, "utf-16": 6, "utf-32": 5}


@pytest.mark.parametrize("encoding", ["utf-8", "utf-16", "utf-32"])
async def test_negotiated_encoding_counts_columns(encoding: str) -> None:
    config = ClientServerConfig(server_command=SERVER, client_factory=make_client)
    client = await config.start()
    assert isinstance(client, Client)
    try:
        params = initialize_params()
        if encoding != "utf-16":
            params.capabilities.general = types.GeneralClientCapabilities(
                position_encodings=[encoding, "utf-16"])
        result = await client.initialize_session(params)
        assert result.capabilities.position_encoding == encoding
        sync = result.capabilities.text_document_sync
        assert isinstance(sync, types.TextDocumentSyncOptions)
        assert sync.change == types.TextDocumentSyncKind.Incremental
        uri, diagnostics = await client.opened(TEXT)
        (error,) = [d for d in diagnostics if d.code == "E0102"]
        assert error.range == types.Range(types.Position(1, 4),
                                          types.Position(1, EMOJI_END[encoding]))
        # Append to the end of line 1, counted in the negotiated units: a wrong count
        # would land inside the comment, where nothing is an error.
        line = TEXT.splitlines()[0]
        end = {"utf-8": len(line.encode()), "utf-16": len(line), "utf-32": len(line)}[encoding]
        client.change(uri, 2, ((0, end, 0, end), "\n(MOV"))
        after = await client.diagnostics_of(uri, 2)
        assert [(d.code, d.range.start.line) for d in after if d.code == "E0101"] == [
            ("E0101", 1)]
    finally:
        await client.shutdown_session()
        await client.stop()  # type: ignore[no-untyped-call]
