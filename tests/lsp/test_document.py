"""The document model and column conversion, in process: properties over many edits."""

from __future__ import annotations

from hypothesis import example, given, settings
from hypothesis import strategies as st
from lsprotocol import types

from rl1.compiler.checker import check_line
from rl1.compiler.frontend.diagnostics import sort_key
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.strategies import lines
from rl1.lsp.document import MAX_ANALYSED_LINE, Document
from rl1.lsp.positions import UTF8, UTF16, UTF32, Columns
from rl1.lsp.tokens import TokenHistory, encode

PIECES = st.sampled_from([
    "A=1", ":10 B=A+2", "?B>#10", "(MOV 3,3)", "(MVI", "'日本語😀", "ｺﾒﾝﾄ", "\n", "\r\n",
    "\r", " ", "#", ";", "\x00", "\u2028", "\x0c", "$FF", "é",
])
TEXT = st.lists(st.one_of(PIECES, lines()), max_size=12).map("".join)
ENCODINGS = st.sampled_from([UTF8, UTF16, UTF32])


def units(text: str, encoding: str) -> int:
    if encoding == UTF8:
        return len(text.encode("utf-8", "surrogatepass"))
    if encoding == UTF16:
        return len(text.encode("utf-16-le", "surrogatepass")) // 2
    return len(text)


def reference_offset(text: str, position: types.Position, encoding: str) -> int:
    """Code-point offset of a client position; the obvious, slow way."""
    # not str.splitlines: it knows more line breaks than LSP's three
    lines, current = [], ""
    index = 0
    while index < len(text):
        current += text[index]
        if text[index] == "\r" and text[index + 1 : index + 2] == "\n":
            current += "\n"
            index += 1
        if text[index] in "\r\n":
            lines.append(current)
            current = ""
        index += 1
    lines.append(current)
    if position.line >= len(lines):
        return len(text)
    start = sum(map(len, lines[: position.line]))
    content = lines[position.line].rstrip("\r\n")
    for column in range(len(content) + 1):
        if units(content[:column], encoding) > position.character:
            return start + column - 1
    return start + len(content)


@st.composite
def changes(draw: st.DrawFn) -> types.TextDocumentContentChangeEvent:
    if draw(st.integers(0, 9)) == 0:
        return types.TextDocumentContentChangeWholeDocument(text=draw(TEXT))
    a, b, c, d = (draw(st.integers(0, 8)) for _ in range(4))
    start, end = sorted([types.Position(a, b), types.Position(c, d)],
                        key=lambda p: (p.line, p.character))
    return types.TextDocumentContentChangePartial(range=types.Range(start, end), text=draw(TEXT))


_LINE_INSERTED_ABOVE_PARSED_LINES = [
    (types.TextDocumentContentChangePartial(
        range=types.Range(types.Position(0, 0), types.Position(0, 0)), text="\n"), 0, True),
]


@settings(max_examples=300, deadline=None)
@given(text=TEXT, edits=st.lists(st.tuples(changes(), st.integers(0, 9), st.booleans()),
                                 max_size=6), encoding=ENCODINGS)
@example(text="A=1\nB=2\n", edits=_LINE_INSERTED_ABOVE_PARSED_LINES, encoding=UTF16)
def test_edits_keep_text_and_syntax_as_if_parsed_afresh(
        text: str, edits: list[tuple[types.TextDocumentContentChangeEvent, int, bool]],
        encoding: str) -> None:
    columns = Columns(encoding)
    document = Document("file:///t.rob", text, 1)
    document.program()  # fill the cache so that edits must keep it right
    for change, prepared, look in edits:
        if isinstance(change, types.TextDocumentContentChangeWholeDocument):
            text = change.text
        else:
            low = reference_offset(text, change.range.start, encoding)
            high = reference_offset(text, change.range.end, encoding)
            text = text[:low] + change.text + text[high:]
        document.apply(change, columns)
        assert document.text() == text
        # As the server does: prepare some lines ahead (a slice), look at the program.
        document.prepare(1, min(prepared, document.program_lines()))
        if look:
            assert document.program() == parse_program(text)[0]
    program, syntax = parse_program(text)
    assert document.program() == program
    per_line = syntax + [d for line in program.lines for d in check_line(line)]
    assert sorted(document.problems(), key=sort_key) == sorted(per_line, key=sort_key)


@settings(max_examples=300, deadline=None)
@given(text=st.text(max_size=20), encoding=ENCODINGS, column=st.integers(0, 25))
def test_columns_round_trip_and_count_code_units(text: str, encoding: str, column: int) -> None:
    columns = Columns(encoding)
    client = columns.to_client(text, column)
    assert client == units(text[:column], encoding)
    assert columns.from_client(text, client) == min(column, len(text))


def test_japanese_comment_positions_in_each_encoding() -> None:
    text = "A=1 '日本語😀x"
    end = len(text)
    assert Columns(UTF32).to_client(text, end) == 10
    assert Columns(UTF16).to_client(text, end) == 11
    assert Columns(UTF8).to_client(text, end) == 5 + 9 + 4 + 1
    # the middle of the emoji's surrogate pair rounds down to the emoji
    assert Columns(UTF16).from_client(text, 9) == 8


@settings(max_examples=200, deadline=None)
@given(text=TEXT, edit=changes())
def test_semantic_token_deltas_rebuild_the_new_tokens(
        text: str, edit: types.TextDocumentContentChangeEvent) -> None:
    columns = Columns(UTF16)
    document = Document("file:///t.rob", text, 1)
    history = TokenHistory()
    before = history.full(document, columns)
    document.apply(edit, columns)
    delta = history.delta(document, columns, before.result_id or "")
    assert isinstance(delta, types.SemanticTokensDelta)
    data = list(before.data)
    for change in delta.edits:
        data[change.start : change.start + change.delete_count] = list(change.data or [])
    assert data == encode(document, columns)


def test_a_document_with_an_overlong_line_is_too_large_until_the_line_is_shortened() -> None:
    columns = Columns()
    long = "A" * (MAX_ANALYSED_LINE + 1)
    document = Document("file:///t.rob", f"B=1\n{long}\n(END)\n", 1)
    assert document.too_large and document.longest_line() == (2, len(long))
    document.apply(types.TextDocumentContentChangePartial(   # a second one, then both go
        range=types.Range(types.Position(0, 0), types.Position(0, 0)), text=long + "\n"),
        columns)
    document.apply(types.TextDocumentContentChangePartial(   # the second shortened
        range=types.Range(types.Position(2, 3), types.Position(2, len(long))), text=""),
        columns)
    assert document.too_large and document.longest_line() == (1, len(long))
    document.apply(types.TextDocumentContentChangePartial(
        range=types.Range(types.Position(0, 0), types.Position(2, 0)), text=""), columns)
    assert not document.too_large and document.text() == "AAA\n(END)\n"
