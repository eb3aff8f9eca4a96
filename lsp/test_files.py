"""A test file of `rl1c test` (spec/tests.md, `*.tests.toml`) open in the editor: what
`rl1c test` would refuse in it, as a diagnostic on its line, from the same loader
(compiler/test_file.py). Such a document is TOML, not RL/I: the server analyses it for
nothing else."""

from __future__ import annotations

import os
from urllib.parse import unquote, urlparse

from lsprotocol import types

from rl1.compiler.frontend import ast
from rl1.compiler.test_file import is_test_file, load_test_file
from rl1.vm.config import ConfigError

from .document import Document
from .positions import Columns

SOURCE = "rl1 test file"


def is_test_file_uri(uri: str) -> bool:
    """Whether the document `uri` is a test file, by its name."""
    return is_test_file(unquote(urlparse(uri).path))


def test_file_diagnostics(document: Document, columns: Columns) -> list[types.Diagnostic]:
    """What keeps the test file `document` from being used, on its line (the first when
    the line is not known); none for a valid one."""
    name = os.path.basename(unquote(urlparse(document.uri).path))
    try:
        load_test_file(document.text().encode("utf-8", "surrogatepass"), name)
    except ConfigError as error:
        line = error.line or 1
        text = document.line_text(line)
        span = ast.Span(line, 1, line, max(len(text), 1) + 1)
        where = f"{error.where}: " if error.where else ""
        return [types.Diagnostic(range=document.range_of(span, columns),
                                 message=where + error.detail,
                                 severity=types.DiagnosticSeverity.Error, source=SOURCE)]
    return []
