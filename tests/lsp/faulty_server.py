"""rl1-lsp with a bug planted in hover, to test that a failing feature is answered with
an error and the server keeps serving. Run as a script by test_robustness.py."""

from __future__ import annotations

from lsprotocol import types

from rl1.lsp import hover, server
from rl1.lsp.document import Document
from rl1.lsp.positions import Columns


def broken_hover(document: Document, position: types.Position,
                 columns: Columns) -> types.Hover | None:
    raise RuntimeError("planted failure in hover")


hover.hover = broken_hover
server.main()
