"""A test file of `rl1c test` (*.tests.toml) open in the editor: the server publishes what
`rl1c test` would refuse in it, on its line, and nothing once it is valid; it answers no
RL/I request on it (it is TOML)."""

from __future__ import annotations

import pytest
from conftest import Client
from lsprotocol import types

pytestmark = pytest.mark.asyncio(loop_scope="module")

VALID = '[[test]]\nname = "it ends"\nprogram = "main.rob"\nexpect.variables = { A = 1 }\n'


async def test_a_schema_error_is_a_diagnostic_on_its_line(client: Client) -> None:
    text = VALID.replace("{ A = 1 }", "{ AB = 1 }")
    _, (diagnostic,) = await client.opened(text, "file:///work/robot/main.tests.toml")
    assert diagnostic.range.start == types.Position(3, 0)
    assert diagnostic.range.end == types.Position(3, len(text.splitlines()[3]))
    assert diagnostic.severity == types.DiagnosticSeverity.Error
    assert diagnostic.message == ("test[0].expect.variables.AB: expected a variable's name, "
                                  "A-Z, a-z or @")
    assert diagnostic.source == "rl1 test file"


async def test_a_valid_file_has_none_and_an_edit_is_checked_again(client: Client) -> None:
    uri, diagnostics = await client.opened(VALID, "file:///work/robot/rl1.tests.toml")
    assert diagnostics == []
    client.change(uri, 2, ((1, 0, 1, 0), "name = \"again\"\n"))  # a key twice: invalid TOML
    (broken,) = await client.diagnostics_of(uri, 2)
    assert broken.range.start.line == 2  # where the second `name` is
    assert broken.message.startswith("invalid TOML")
    client.change(uri, 3, ((1, 0, 2, 0), ""))
    assert await client.diagnostics_of(uri, 3) == []


async def test_checks_across_keys_are_shown_too(client: Client) -> None:
    text = VALID + 'world = "w.toml"\nsensors = "s.toml"\n'
    _, (diagnostic,) = await client.opened(text, "file:///work/robot/both.tests.toml")
    assert diagnostic.range.start.line == 5
    assert "test[0].sensors: a test runs on a world or on a sensor script, not both" in \
        diagnostic.message


async def test_rl1_requests_on_a_test_file_are_answered_empty(client: Client) -> None:
    uri = client.open(VALID, "file:///work/robot/hover.tests.toml")
    await client.diagnostics_of(uri, 1)
    hover = await client.text_document_hover_async(types.HoverParams(
        types.TextDocumentIdentifier(uri), types.Position(2, 2)))
    assert hover is None


async def test_a_toml_file_of_another_name_is_not_a_test_file(client: Client) -> None:
    # Only the name tells: any other document is RL/I, whose syntax this is not.
    _, diagnostics = await client.opened(VALID, "file:///work/robot/notes.toml")
    assert diagnostics and all(d.source == "rl1" for d in diagnostics)
