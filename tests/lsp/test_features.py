"""Each language feature end to end, over stdio, on one small program."""

from __future__ import annotations

import pytest
from conftest import SERVER, Client, initialize_params, make_client, position_of
from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pytest_lsp import ClientServerConfig

from rl1.compiler.analysis import analyze, fix
from rl1.compiler.formatter import format_text
from rl1.vm.language import BUILTINS, VARIABLES

pytestmark = pytest.mark.asyncio(loop_scope="module")

PROGRAM = """'demo 日本語のコメント😀
'second comment line
:10 (MVI 3,3,50); A=(IMG)
?A>#10
(CAM A 90); B=(ULT b)
C=$FFFF+x; (mov 1,1)
#20
:20 (MOV 1,1); (TRC 3)
?C=#10
(MVX 0,0)
(END)
:96 (MOV 0,0)
"""


def doc(uri: str) -> types.TextDocumentIdentifier:
    return types.TextDocumentIdentifier(uri)


async def open_program(client: Client, text: str = PROGRAM) -> str:
    uri, _ = await client.opened(text)
    return uri


async def hover_text(client: Client, uri: str, text: str, needle: str, offset: int = 0) -> str:
    result = await client.text_document_hover_async(
        types.HoverParams(doc(uri), position_of(text, needle, offset)))
    assert result is not None
    assert isinstance(result.contents, types.MarkupContent)
    return result.contents.value


# Diagnostics with related information -------------------------------------------------


async def test_duplicate_label_diagnostic_points_at_the_first_definition(client: Client) -> None:
    text = ":30 A=1\n:30 B=2\n(END)\n"
    uri, diagnostics = await client.opened(text)
    related = [d for d in diagnostics if d.related_information]
    assert related, diagnostics
    (info,) = related[0].related_information or []
    assert info.location.uri == uri
    assert info.location.range.start == types.Position(0, 0)
    assert related[0].range.start.line == 1


# Hover ----------------------------------------------------------------------------------


async def test_hover_on_a_builtin_shows_the_tables_facts(client: Client) -> None:
    uri = await open_program(client)
    text = await hover_text(client, uri, PROGRAM, "MVI")
    mvi = BUILTINS["MVI"].forms[0]
    for param in mvi.params:
        assert f"`{param.name}`: {param.meaning}, {param.low}..{param.high}" in text
    assert mvi.summary in text
    assert "waits" in text
    img = await hover_text(client, uri, PROGRAM, "IMG")
    for variable in "wxyz":
        assert f"`{variable}`" in img
    assert BUILTINS["IMG"].forms[0].result or "" in img


async def test_hover_on_a_selector_form_and_on_a_call_that_returns_at_once(client: Client) -> None:
    uri = await open_program(client)
    cam = await hover_text(client, uri, PROGRAM, "CAM A", 4)
    assert "Pan the camera to an angle" in cam
    mov = await hover_text(client, uri, PROGRAM, "MOV 1,1)", 0)
    assert "returns at once" in mov


async def test_hover_on_variables(client: Client) -> None:
    uri = await open_program(client)
    reserved = await hover_text(client, uri, PROGRAM, "x; (mov")
    assert "Reserved" in reserved and "(IMG)" in reserved
    plain = await hover_text(client, uri, PROGRAM, "A=(IMG)")
    assert "Not reserved" in plain
    assert f"index {VARIABLES.index('A')}" in plain


async def test_hover_on_a_label_and_a_jump(client: Client) -> None:
    uri = await open_program(client)
    definition = await hover_text(client, uri, PROGRAM, ":10")
    assert "Defined on line 3" in definition
    assert "lines 4, 9" in definition
    handler = await hover_text(client, uri, PROGRAM, ":96")
    assert "Tracing handler" in handler and "mode 3" in handler


async def test_hover_on_constants(client: Client) -> None:
    uri = await open_program(client)
    text = await hover_text(client, uri, PROGRAM, "$FFFF")
    assert "16-bit value -1" in text and "$FFFF" in text and "unsigned 65535" in text
    big = "A=40000\n"
    uri = await open_program(client, big)
    assert "does not fit in 16 bits" in await hover_text(client, uri, big, "40000")


async def test_hover_range_is_in_utf16_after_a_japanese_line(client: Client) -> None:
    text = "'コメント😀\nA=1 'ｺﾒﾝﾄ\n(MOV 3,3)\n"
    uri = await open_program(client, text)
    result = await client.text_document_hover_async(
        types.HoverParams(doc(uri), types.Position(2, 2)))
    assert result is not None and result.range == types.Range(
        types.Position(2, 1), types.Position(2, 4))


# Completion and signature help ---------------------------------------------------------


async def complete(client: Client, text: str, line: int, character: int
                   ) -> list[types.CompletionItem]:
    uri = await open_program(client, text)
    result = await client.text_document_completion_async(types.CompletionParams(
        doc(uri), types.Position(line, character)))
    assert isinstance(result, list)
    return result


async def test_completion_of_mnemonics_has_argument_snippets(client: Client) -> None:
    items = await complete(client, "(MV", 0, 3)
    by_label = {item.label: item for item in items}
    mvi = by_label["MVI"]
    assert mvi.insert_text_format == types.InsertTextFormat.Snippet
    assert isinstance(mvi.text_edit, types.TextEdit)
    assert mvi.text_edit.new_text == "MVI ${1:l},${2:r},${3:cm})"
    assert mvi.text_edit.range == types.Range(types.Position(0, 1), types.Position(0, 3))
    assert {"CAM A", "CAM Z", "ULT A"} <= set(by_label)
    assert set(BUILTINS) <= {label.split()[0] for label in by_label}


async def test_completion_of_selectors(client: Client) -> None:
    items = await complete(client, "B=(ULT ", 0, 7)
    assert [item.label for item in items] == ["A", "B", "C", "D"]
    cam = await complete(client, "(CAM ", 0, 5)
    assert {item.label for item in cam} == {"Z", "U", "D", "A", "P", "R"}


async def test_completion_of_labels_after_a_jump(client: Client) -> None:
    text = ":10 A=1\n:20 B=2\n?A<#\n#2"
    items = await complete(client, text, 2, 4)
    assert [item.label for item in items] == ["10", "20"]
    uri = await open_program(client, text)
    result = await client.text_document_completion_async(types.CompletionParams(
        doc(uri), types.Position(3, 2)))
    assert isinstance(result, list)
    edit = result[0].text_edit
    assert isinstance(edit, types.TextEdit)
    assert edit.range == types.Range(types.Position(3, 1), types.Position(3, 2))


async def test_completion_of_variables_and_none_in_comments(client: Client) -> None:
    items = await complete(client, "A=B+", 0, 4)
    assert [item.label for item in items] == list(VARIABLES)
    assert await complete(client, "A=1 ' B+", 0, 8) == []


async def test_signature_help_follows_the_argument(client: Client) -> None:
    text = "(MVI 3,3,\n(CAM A 9\n"
    uri = await open_program(client, text)
    help_ = await client.text_document_signature_help_async(types.SignatureHelpParams(
        doc(uri), types.Position(0, 9)))
    assert help_ is not None
    assert help_.signatures[0].label == "(MVI l,r,cm)"
    assert help_.active_parameter == 2
    cam = await client.text_document_signature_help_async(types.SignatureHelpParams(
        doc(uri), types.Position(1, 8)))
    assert cam is not None and cam.active_signature is not None
    chosen = cam.signatures[cam.active_signature]
    assert chosen.label == "(CAM A deg)"
    assert cam.active_parameter == 1
    assert chosen.parameters is not None
    assert chosen.parameters[1].label == (7, 10)
    assert chosen.label[7:10] == "deg"


# Navigation ----------------------------------------------------------------------------


async def test_definition_of_a_jump(client: Client) -> None:
    uri = await open_program(client)
    found = await client.text_document_definition_async(types.DefinitionParams(
        doc(uri), position_of(PROGRAM, "#10", 1)))
    assert isinstance(found, list)
    assert [loc.range.start for loc in found] == [types.Position(2, 0)]
    cond = await client.text_document_definition_async(types.DefinitionParams(
        doc(uri), position_of(PROGRAM, "?C=#10", 4)))
    assert isinstance(cond, list) and cond[0].range.start == types.Position(2, 0)


async def test_references_and_highlights_of_a_label(client: Client) -> None:
    uri = await open_program(client)
    refs = await client.text_document_references_async(types.ReferenceParams(
        context=types.ReferenceContext(include_declaration=True), text_document=doc(uri),
        position=position_of(PROGRAM, ":10")))
    assert [r.range.start.line for r in refs or []] == [2, 3, 8]
    highlights = await client.text_document_document_highlight_async(
        types.DocumentHighlightParams(doc(uri), position_of(PROGRAM, "#10", 1)))
    kinds = [(h.range.start.line, h.kind) for h in highlights or []]
    assert kinds == [(2, types.DocumentHighlightKind.Write), (3, types.DocumentHighlightKind.Read),
                     (8, types.DocumentHighlightKind.Read)]


async def test_references_of_a_variable(client: Client) -> None:
    uri = await open_program(client)
    refs = await client.text_document_references_async(types.ReferenceParams(
        context=types.ReferenceContext(include_declaration=True), text_document=doc(uri),
        position=position_of(PROGRAM, "C=$")))
    assert [r.range.start.line for r in refs or []] == [5, 8]


async def test_highlights_of_a_variable_mark_writes_and_reads(client: Client) -> None:
    text = "A=1; B=A+2\nA++; ?A>#10\n(MOV A,B)\n"
    uri = await open_program(client, text)
    found = await client.text_document_document_highlight_async(
        types.DocumentHighlightParams(doc(uri), position_of(text, "A+2")))
    write, read = types.DocumentHighlightKind.Write, types.DocumentHighlightKind.Read
    assert [(h.range.start.line, h.range.start.character, h.kind) for h in found or []] == [
        (0, 0, write), (0, 7, read), (1, 0, write), (1, 6, read), (2, 5, read)]
    refs = await client.text_document_references_async(types.ReferenceParams(
        context=types.ReferenceContext(include_declaration=False), text_document=doc(uri),
        position=position_of(text, "#10", 1)))
    assert [r.range.start for r in refs or []] == [types.Position(1, 8)]


async def test_rename_a_label_renumbers_definition_and_jumps(client: Client) -> None:
    uri = await open_program(client)
    prepared = await client.text_document_prepare_rename_async(types.PrepareRenameParams(
        doc(uri), position_of(PROGRAM, "#10", 2)))
    assert isinstance(prepared, types.PrepareRenamePlaceholder)
    assert prepared.placeholder == "10"
    edit = await client.text_document_rename_async(types.RenameParams(
        doc(uri), position_of(PROGRAM, "#10", 2), new_name="55"))
    assert edit is not None and edit.changes is not None
    edits = sorted(edit.changes[uri], key=lambda e: e.range.start.line)
    assert [(e.range.start.line, e.new_text) for e in edits] == [
        (2, ":55"), (3, "#55"), (8, "#55")]


@pytest.mark.parametrize(("new_name", "message"), [
    ("20", "already defined on line 8"),
    ("100", "two digits"),
    ("5", "two digits"),
    ("ab", "not a label number"),
    ("97", "tracing handler"),
])
async def test_rename_refuses_with_a_clear_message(client: Client, new_name: str,
                                                   message: str) -> None:
    uri = await open_program(client)
    with pytest.raises(JsonRpcException, match=message):
        await client.text_document_rename_async(types.RenameParams(
            doc(uri), position_of(PROGRAM, ":10"), new_name=new_name))


async def test_prepare_rename_refuses_what_is_not_a_label(client: Client) -> None:
    uri = await open_program(client)
    with pytest.raises(JsonRpcException, match="only labels can be renamed"):
        await client.text_document_prepare_rename_async(types.PrepareRenameParams(
            doc(uri), position_of(PROGRAM, "A=(IMG)")))
    with pytest.raises(JsonRpcException, match="handler label"):
        await client.text_document_prepare_rename_async(types.PrepareRenameParams(
            doc(uri), position_of(PROGRAM, ":96")))


async def test_document_symbols_are_the_labels(client: Client) -> None:
    uri = await open_program(client)
    symbols = await client.text_document_document_symbol_async(
        types.DocumentSymbolParams(doc(uri)))
    assert [(s.name, s.range.start.line, s.range.end.line) for s in symbols or []
            if isinstance(s, types.DocumentSymbol)] == [
                (":10", 2, 6), (":20", 7, 10), (":96", 11, 11)]


async def test_folding_ranges_fold_sections_and_comment_blocks(client: Client) -> None:
    uri = await open_program(client)
    ranges = await client.text_document_folding_range_async(types.FoldingRangeParams(doc(uri)))
    found = {(r.start_line, r.end_line, r.kind) for r in ranges or []}
    assert found == {(2, 6, types.FoldingRangeKind.Region), (7, 10, types.FoldingRangeKind.Region),
                     (0, 1, types.FoldingRangeKind.Comment)}


# Semantic tokens --------------------------------------------------------------------------


def decode(data: list[int]) -> list[tuple[int, int, int, int]]:
    tokens, line, start = [], 0, 0
    for index in range(0, len(data), 5):
        delta_line, delta_start, length, kind, _ = data[index : index + 5]
        line += delta_line
        start = start + delta_start if delta_line == 0 else delta_start
        tokens.append((line, start, length, kind))
    return tokens


async def test_semantic_tokens_full_and_delta(client: Client) -> None:
    text = "'日本語😀\n:10 A=x+1; ?A>#10\n"
    uri = await open_program(client, text)
    full = await client.text_document_semantic_tokens_full_async(
        types.SemanticTokensParams(doc(uri)))
    assert full is not None and full.result_id
    tokens = decode(list(full.data))
    label, function, _, variable, number, operator, keyword, comment = range(8)
    assert tokens == [
        (0, 0, 6, comment),  # UTF-16: the quote, three kanji and a surrogate pair
        (1, 0, 3, label), (1, 4, 1, variable), (1, 6, 1, variable), (1, 7, 1, operator),
        (1, 8, 1, number), (1, 11, 1, keyword), (1, 12, 1, variable), (1, 13, 1, operator),
        (1, 14, 3, label),
    ]
    client.change(uri, 2, ((1, 8, 1, 9), "(IMG)"))
    await client.diagnostics_of(uri, 2)
    delta = await client.text_document_semantic_tokens_full_delta_async(
        types.SemanticTokensDeltaParams(doc(uri), previous_result_id=full.result_id))
    assert isinstance(delta, types.SemanticTokensDelta)
    data = list(full.data)
    for edit in delta.edits:
        data[edit.start : edit.start + edit.delete_count] = list(edit.data or [])
    again = await client.text_document_semantic_tokens_full_async(
        types.SemanticTokensParams(doc(uri)))
    assert again is not None and data == list(again.data)
    assert (1, 9, 3, function) in decode(data)


# Formatting, code actions, inlay hints ------------------------------------------------------


async def test_formatting_uses_the_project_formatter(client: Client) -> None:
    text = ":10   A = 1 ;B=2\n(mov 3 , 3)\n"
    uri = await open_program(client, text)
    edits = await client.text_document_formatting_async(types.DocumentFormattingParams(
        doc(uri), types.FormattingOptions(tab_size=4, insert_spaces=True)))
    assert edits is not None and len(edits) == 1
    assert edits[0].new_text == format_text(text)
    ranged = await client.text_document_range_formatting_async(
        types.DocumentRangeFormattingParams(
            doc(uri), types.Range(types.Position(1, 0), types.Position(1, 3)),
            types.FormattingOptions(tab_size=4, insert_spaces=True)))
    assert ranged is not None
    assert [(e.range.start.line, e.new_text) for e in ranged] == [
        (1, format_text("(mov 3 , 3)\n").rstrip("\n"))]


async def actions_at(client: Client, uri: str, line: int) -> list[types.CodeAction]:
    found = await client.text_document_code_action_async(types.CodeActionParams(
        doc(uri), types.Range(types.Position(line, 0), types.Position(line, 0)),
        types.CodeActionContext(diagnostics=[])))
    return [a for a in found or [] if isinstance(a, types.CodeAction)]


async def test_quick_fixes_come_from_the_checker(client: Client) -> None:
    uri = await open_program(client)
    fixes = {a.title: a for a in await actions_at(client, uri, 9)
             if a.kind == types.CodeActionKind.QuickFix}
    mvi = fixes["write `MVI`"]
    assert mvi.edit is not None and mvi.edit.changes is not None
    (edit,) = mvi.edit.changes[uri]
    # What the fix changes: `MVX` made `MVI`.
    assert (edit.range, edit.new_text) == (
        types.Range(types.Position(9, 3), types.Position(9, 4)), "I")
    assert mvi.diagnostics and mvi.diagnostics[0].code == "E0501"
    upper = {a.title for a in await actions_at(client, uri, 5)}
    assert "write `MOV`" in upper
    handler = [a for a in await actions_at(client, uri, 2) if ":97" in a.title]
    assert handler, "the checker offers to add the missing :97 handler"
    assert handler[0].edit is not None and handler[0].edit.changes is not None
    (added,) = handler[0].edit.changes[uri]
    # After the last line (the text both ways ends with a line end, which the edit keeps).
    assert (added.range.start, added.range.end, added.new_text) == (
        types.Position(12, 0), types.Position(12, 0), ":97 (MOV 0,0); (END)\n")


@pytest.mark.parametrize("line, allowed", [
    ("(TRC 3); (MVI 3,3,100)", "(TRC 3); (MVI 3,3,100) ' rl1: allow W0301"),
    ("(TRC 3); (MVI 3,3,100) 'go", "(TRC 3); (MVI 3,3,100) 'go rl1: allow W0301"),
])
async def test_a_warning_can_be_allowed_on_its_line(client: Client, line: str,
                                                    allowed: str) -> None:
    text = line + "\n(END)\n"
    uri = await open_program(client, text)
    (allow,) = [a for a in await actions_at(client, uri, 0) if a.title.startswith("Allow")]
    assert allow.title.startswith("Allow W0301 on this line")
    assert allow.edit is not None and allow.edit.changes is not None
    (edit,) = allow.edit.changes[uri]
    assert edit.range.start == edit.range.end == types.Position(0, len(line))
    assert line + edit.new_text == allowed
    assert analyze(allowed + "\n(END)\n").diagnostics == []
    # A line whose comment holds a directive already is not offered another.
    directive = await open_program(client, line + " ' rl1: allow W0602\n(END)\n")
    assert not [a for a in await actions_at(client, directive, 0) if a.title.startswith("Allow")]


def applied(text: str, edit: types.TextEdit) -> str:
    """`text` with one LSP edit whose range starts and ends at the start of a line (or
    the end of the text), as the fix-all edit does."""
    lines = text.splitlines(keepends=True)

    def offset(position: types.Position) -> int:
        return sum(len(line) for line in lines[:position.line]) + position.character

    return text[:offset(edit.range.start)] + edit.new_text + text[offset(edit.range.end):]


@pytest.mark.parametrize("text, fixed", [
    # Issue 22: "fix all" made the guesses at misspelt names that --fix leaves alone.
    (":5 (TIM 10); (MOVE 3,3)\n(HLB)\n", ":05 (TIM 10); (MOVE 3,3)\n(HLB)\n"),
    (PROGRAM, PROGRAM.replace("(mov 1,1)", "(MOV 1,1)").replace("(ULT b)", "(ULT B)")),
    ("(mov 3,3)\r\nA=1", "(MOV 3,3)\r\nA=1\r\n(END)"),
])
async def test_fix_all_makes_the_safe_fixes_check_fix_makes(client: Client, text: str,
                                                            fixed: str) -> None:
    uri = await open_program(client, text)
    actions = await actions_at(client, uri, 0)
    (fix_all,) = [a for a in actions if a.kind == types.CodeActionKind.SourceFixAll]
    assert fix_all.edit is not None and fix_all.edit.changes is not None
    (edit,) = fix_all.edit.changes[uri]
    assert applied(text, edit) == fixed == fix(text).text
    guesses = [a for a in actions if a.diagnostics and a.diagnostics[0].code == "E0501"]
    assert not any(a.is_preferred for a in guesses), "a guess is never made unasked"


async def test_a_client_that_resolves_edits_gets_the_fix_all_edit_on_resolve() -> None:
    """The edit costs a check a round, and editors ask for code actions at every move
    of the cursor: it is made only when the client resolves the action."""
    client = await ClientServerConfig(server_command=SERVER, client_factory=make_client).start()
    assert isinstance(client, Client)
    try:
        params = initialize_params()
        assert params.capabilities.text_document is not None
        params.capabilities.text_document.code_action = types.CodeActionClientCapabilities(
            resolve_support=types.ClientCodeActionResolveOptions(properties=["edit"]))
        result = await client.initialize_session(params)
        options = result.capabilities.code_action_provider
        assert isinstance(options, types.CodeActionOptions) and options.resolve_provider
        text = ":5 (TIM 10); (mov 3,3)\n(MOVE 3,3)\n"
        uri = await open_program(client, text)
        (offered,) = [a for a in await actions_at(client, uri, 0)
                      if a.kind == types.CodeActionKind.SourceFixAll]
        assert offered.edit is None
        resolved = await client.code_action_resolve_async(offered)
        assert resolved.edit is not None and resolved.edit.changes is not None
        (edit,) = resolved.edit.changes[uri]
        assert applied(text, edit) == fix(text).text == ":05 (TIM 10); (MOV 3,3)\n(MOVE 3,3)\n"
        client.change(uri, 2, ((1, 0, 1, 0), "A=1\n"))
        stale = await client.code_action_resolve_async(offered)
        assert stale.edit is None, "an action offered for an older version is not made"
        await client.shutdown_session()
    finally:
        await client.stop()  # type: ignore[no-untyped-call]


async def test_no_fix_all_when_no_safe_fix_is_left(client: Client) -> None:
    uri = await open_program(client, "(HLB)\n(END)\n")
    assert not [a for a in await actions_at(client, uri, 0)
                if a.kind == types.CodeActionKind.SourceFixAll]


async def test_inlay_hints_name_the_arguments(client: Client) -> None:
    text = "(MVI 3,3,50); A=(CAM R)\n(CAM A 90)\n"
    uri = await open_program(client, text)
    hints = await client.text_document_inlay_hint_async(types.InlayHintParams(
        doc(uri), types.Range(types.Position(0, 0), types.Position(2, 0))))
    assert [(h.position.line, h.position.character, h.label) for h in hints or []] == [
        (0, 5, "l:"), (0, 7, "r:"), (0, 9, "cm:"), (1, 7, "deg:")]
