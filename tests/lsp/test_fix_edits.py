"""A quick fix's edit, made by an editor as LSP says (positions in UTF-16 code units,
each range replaced in the text, from the last to the first), writes what `rl1c check
--fix` writes: apply_edits keeps a line emptied between a lone CR and an LF apart, and
writes a line break as the document's first line end, which the fix's edits sent as
given did not say (an editor joined the two lines)."""

from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import assume, given, settings
from hypothesis import strategies as st
from lsprotocol import types
from support.checker import FIX_TEXTS, an_edit
from support.cli import rl1c

from rl1.compiler.frontend.diagnostics import Edit, Fix
from rl1.compiler.frontend.edits import apply_edits
from rl1.compiler.frontend.source import LINE_BREAK
from rl1.lsp.actions import code_actions, fix_edit
from rl1.lsp.checking import diagnose
from rl1.lsp.document import Document
from rl1.lsp.positions import UTF16, Columns

URI = "file:///work/fixed.rob"
ENDS = st.sampled_from(["\n", "\r", "\r\n"])


def made_by_an_editor(text: str, edit: types.WorkspaceEdit) -> str:
    """`text` with the edit's changes made as an LSP client makes them."""
    assert edit.changes is not None and list(edit.changes) == [URI]
    starts = [0, *(found.end() for found in LINE_BREAK.finditer(text))]

    def offset(position: types.Position) -> int:
        assert position.line < len(starts), f"{position} is past the text's last line"
        start = starts[position.line]
        found = LINE_BREAK.search(text, start)
        line = text[start:found.start() if found else len(text)]
        units = 0
        for column, character in enumerate(line):
            if units == position.character:
                return start + column
            units += 2 if ord(character) > 0xFFFF else 1
        assert units == position.character, f"{position} is not at a character of {line!r}"
        return start + len(line)

    places = [(offset(one.range.start), offset(one.range.end), one.new_text)
              for one in edit.changes[URI]]
    for start, end, new_text in sorted(places, reverse=True):
        assert start <= end
        text = text[:start] + new_text + text[end:]
    return text


def _overlap(one: Edit, other: Edit) -> bool:
    a, b = one.span, other.span
    return (a.line, a.column) < (b.end_line, b.end_column) \
        and (b.line, b.column) < (a.end_line, a.end_column)


@settings(max_examples=1500, deadline=None)
@given(st.text(alphabet="AB=1 \r\n日😀", max_size=30),
       st.lists(an_edit([*FIX_TEXTS, "\n"]), min_size=1, max_size=3))
def test_a_fixs_edit_made_by_an_editor_is_what_apply_edits_makes(text: str,
                                                                 edits: list[Edit]) -> None:
    assume(not any(_overlap(one, other) for index, one in enumerate(edits)
                   for other in edits[:index]))
    document = Document(URI, text, 1)
    edit = fix_edit(document, Fix("a fix", tuple(edits)), Columns(UTF16))
    assert made_by_an_editor(text, edit) == apply_edits(text, edits)


@st.composite
def an_unused_label_alone_on_its_line(draw: st.DrawFn) -> str:
    """A program whose only fix is W0205's (a label alone on its line that nothing jumps
    to), its lines ended with LF, CR and CRLF at random."""
    lines = draw(st.lists(st.sampled_from(["A=1", "(TIM 10)", "", "' note 日本"]),
                          max_size=4))
    lines.insert(draw(st.integers(0, len(lines))), ":07")
    lines.append("(END)")
    ends = draw(st.lists(ENDS, min_size=len(lines), max_size=len(lines)))
    ends[-1] = draw(ENDS | st.just(""))
    return "".join(line + end for line, end in zip(lines, ends, strict=True))


def quick_fixes(text: str) -> list[types.CodeAction]:
    """The quick fixes the server offers on any line of `text`."""
    document = Document(URI, text, 1)
    everywhere = types.Range(types.Position(0, 0), types.Position(document.line_count, 0))
    return [action for action in code_actions(document, diagnose(document).diagnostics,
                                              everywhere, ["quickfix"], Columns(UTF16))
            if not action.title.startswith("Allow")]


@settings(max_examples=100, deadline=None)
@given(an_unused_label_alone_on_its_line())
def test_removing_an_unused_label_writes_what_check_fix_writes(text: str) -> None:
    (removal,) = quick_fixes(text)
    assert removal.title == "remove `:07`" and removal.edit is not None
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder, "fixed.rob")
        path.write_bytes(text.encode())
        result = rl1c("check", "--fix", "--unsafe-fixes", path)
        assert result.exit_code == 0, result.output
        fixed = path.read_bytes()
    assert made_by_an_editor(text, removal.edit).encode() == fixed
    assert len(LINE_BREAK.findall(fixed.decode())) == len(LINE_BREAK.findall(text))


def test_a_line_emptied_between_a_cr_and_an_lf_is_kept_apart() -> None:
    # An editor made the removal as given: '\r\n', a line less.
    (removal,) = quick_fixes("A=1\r:07\n(END)\n")
    assert removal.edit is not None and removal.edit.changes is not None
    (edit,) = removal.edit.changes[URI]
    assert (edit.range, edit.new_text) == (
        types.Range(types.Position(1, 0), types.Position(2, 0)), "\r")
    assert made_by_an_editor("A=1\r:07\n(END)\n", removal.edit) == "A=1\r\r(END)\n"


def test_a_line_break_in_a_fix_is_the_documents_first_line_end() -> None:
    text = "(TRC 3); (MVI 3,3,100)\r\n(END)"
    (handler,) = quick_fixes(text)
    assert handler.title.startswith("add the handler") and handler.edit is not None
    assert made_by_an_editor(text, handler.edit) == \
        "(TRC 3); (MVI 3,3,100)\r\n(END)\r\n:97 (MOV 0,0); (END)"
