"""Document sync and diagnostics, end to end: what is published agrees with the
compiler's own `analyze` of the same text, after any sequence of incremental edits."""

from __future__ import annotations

import asyncio
import re
from collections.abc import Sequence
from pathlib import Path

import pytest
from conftest import TIMEOUT, Client
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lsprotocol import types
from support import SAMPLE

from rl1.compiler.analysis import analyze
from rl1.compiler.strategies import lines

pytestmark = pytest.mark.asyncio(loop_scope="module")

SAMPLE_TEXT = SAMPLE.read_text(encoding="utf-8")


def expected(text: str) -> list[tuple[str, int, int, str]]:
    """(code, line, column, message) of what `rl1c check` reports, 0-based positions in
    UTF-16 units for the comparison with LSP."""
    lines = re.split(r"\r\n|\r|\n", text)
    found = []
    for d in analyze(text).diagnostics:
        line_text = lines[d.span.line - 1]
        prefix = line_text[: d.span.column - 1]
        message = d.message + (f"\nhelp: {d.help}" if d.help else "")
        found.append((d.code, d.span.line - 1, len(prefix.encode("utf-16-le")) // 2, message))
    return found


def published(diagnostics: Sequence[types.Diagnostic]) -> list[tuple[str, int, int, str]]:
    return [(str(d.code), d.range.start.line, d.range.start.character, d.message)
            for d in diagnostics]


async def test_sample_program_diagnostics_match_the_compiler(client: Client) -> None:
    _, diagnostics = await client.opened(SAMPLE_TEXT)
    assert published(diagnostics) == expected(SAMPLE_TEXT)


async def test_syntax_error_is_published_with_code_severity_range_and_explanation(
        client: Client) -> None:
    _, diagnostics = await client.opened("A=1\n(MOV 3,3; B=2\n")
    (error,) = [d for d in diagnostics if d.code == "E0101"]
    assert error.code == "E0101"
    assert error.severity == types.DiagnosticSeverity.Error
    assert error.source == "rl1"
    assert error.range.start == types.Position(1, 8)
    assert "close the call with `)`" in error.message
    assert error.code_description is not None
    assert error.code_description.href.startswith("file://")
    assert error.code_description.href.endswith("/explanations/E0101.md")
    path = Path(error.code_description.href.removeprefix("file://"))
    assert path.read_text(encoding="utf-8").startswith("# E0101")


async def test_edit_then_fix_republishes_for_each_version(client: Client) -> None:
    uri, diagnostics = await client.opened("A=1\nB=2\n(END)\n")
    assert published(diagnostics) == expected("A=1\nB=2\n(END)\n")
    client.change(uri, 2, ((1, 0, 1, 3), "(MOV"))
    broken = await client.diagnostics_of(uri, 2)
    assert ("E0101", 1) in [(d.code, d.range.start.line) for d in broken]
    assert published(broken) == expected("A=1\n(MOV\n(END)\n")
    client.change(uri, 3, ((1, 4, 1, 4), " 1,1)"))
    fixed = await client.diagnostics_of(uri, 3)
    assert not [d for d in fixed if str(d.code).startswith("E01")]
    assert published(fixed) == expected("A=1\n(MOV 1,1)\n(END)\n")


async def test_suppression_comments_work_as_in_rl1c_check(client: Client) -> None:
    text = "(TRC 3); (MVI 3,3,100)\n(END)\n"
    uri, diagnostics = await client.opened(text)
    assert [d.code for d in diagnostics] == ["W0301"]
    # Allowing it on its line, as the user types the comment, hides it.
    client.change(uri, 2, ((0, 22, 0, 22), " ' rl1: allow W0301"))
    allowed = await client.diagnostics_of(uri, 2)
    assert allowed == []
    assert published(allowed) == expected("(TRC 3); (MVI 3,3,100) ' rl1: allow W0301\n(END)\n")
    # Moved to another line, the comment allows nothing there: both are shown.
    client.change(uri, 3, ((0, 22, 0, 41), ""), ((1, 5, 1, 5), " ' rl1: allow W0301"))
    moved = await client.diagnostics_of(uri, 3)
    assert sorted(str(d.code) for d in moved) == ["W0107", "W0301"]
    assert published(moved) == expected("(TRC 3); (MVI 3,3,100)\n(END) ' rl1: allow W0301\n")


async def test_the_nearest_rl1_toml_selects_as_for_rl1c_check(client: Client,
                                                              tmp_path: Path) -> None:
    project = tmp_path / "rl1.toml"
    project.write_text('[check]\nignore = ["W0603"]\nwarnings-as-errors = true\n',
                       encoding="utf-8")
    uri = (tmp_path / "sub" / "prog.rob").as_uri()
    _, diagnostics = await client.opened("(MOV 3,3)\n", uri)
    assert [(d.code, d.severity) for d in diagnostics] == [
        ("W0701", types.DiagnosticSeverity.Error)]
    # A broken rl1.toml is said, and the diagnostics are shown as without one.
    project.write_text("[check]\nselct = 1\n", encoding="utf-8")
    client.change(uri, 2, ((0, 9, 0, 9), " "))
    shown = await client.diagnostics_of(uri, 2)
    assert "check.selct: unknown key" in shown[0].message and shown[0].code is None
    assert [(d.code, d.severity) for d in shown[1:]] == [
        ("W0603", types.DiagnosticSeverity.Warning), ("W0701", types.DiagnosticSeverity.Warning)]


async def test_an_rl1_toml_with_a_huge_number_is_said_and_checking_goes_on(
        client: Client, tmp_path: Path) -> None:
    # A value of 5,000 digits was an internal error: the documents under it got no
    # diagnostics, so a repository could switch checking off in the editor.
    (tmp_path / "rl1.toml").write_text("[check]\nwarnings-as-errors = " + "9" * 5000 + "\n",
                                       encoding="utf-8")
    _, shown = await client.opened("(MOV 3,3)\n", (tmp_path / "prog.rob").as_uri())
    assert "rl1.toml:2: check.warnings-as-errors: a number of more than 4300 digits" in \
        shown[0].message
    assert [d.code for d in shown[1:]] == ["W0603", "W0701"]  # checked as without it


async def test_closing_a_document_clears_its_diagnostics(client: Client) -> None:
    uri, diagnostics = await client.opened("A=(\n")
    assert "E0101" in [d.code for d in diagnostics]
    client.text_document_did_close(types.DidCloseTextDocumentParams(
        types.TextDocumentIdentifier(uri)))
    async with asyncio.timeout(TIMEOUT):
        while client.diagnostics[uri]:
            await asyncio.sleep(0.005)


async def test_a_burst_of_edits_never_publishes_a_stale_version(client: Client) -> None:
    uri, _ = await client.opened("A=1\n")
    for version in range(2, 40):
        client.change(uri, version, ((0, 2, 0, 3), "(" if version % 2 else "1"))
    await client.diagnostics_of(uri, 39)
    versions = [p.version or 0 for p in client.published if p.uri == uri]
    assert versions == sorted(versions)
    assert versions[-1] == 39
    assert len(versions) < 39, "a burst of changes is checked less often than it changes"
    # version 39 ends with "(": a syntax error, and only that version's is published
    assert published(client.diagnostics[uri]) == expected("A=(\n")


# Incremental sync against a model of the text ----------------------------------------

LINE_TEXTS = st.one_of(lines(), st.sampled_from([
    "A=1", ":10 B=A+2; ?B>#10", "(MOV 3,3)", "(MVI 1,1,50", "'日本語のコメント😀",
    "C=x-128 'ｺﾒﾝﾄ", "", "  ", "#10", "A=(", "\u3000B=1", "?Z<#99",
]))
BREAKS = st.sampled_from(["\n", "\r\n", "\r"])


def utf16_offset(text: str, line: int, character: int) -> int:
    """The code-point offset of an LSP position in `text`, clamped as the protocol
    suggests: past the end of a line is its end, past the last line is the end."""
    starts = [0] + [m.end() for m in re.finditer(r"\r\n|\r|\n", text)]
    if line >= len(starts):
        return len(text)
    start = starts[line]
    end_match = re.compile(r"\r\n|\r|\n").search(text, start)
    end = end_match.start() if end_match else len(text)
    units = 0
    for index in range(start, end):
        if units >= character:
            return index
        units += 2 if ord(text[index]) > 0xFFFF else 1
        if units > character:
            return index
    return end


@st.composite
def texts(draw: st.DrawFn) -> str:
    lines = draw(st.lists(LINE_TEXTS, max_size=6))
    breaks = [draw(BREAKS) for _ in lines]
    return "".join(line + brk for line, brk in zip(lines, breaks, strict=True))


@st.composite
def edits(draw: st.DrawFn) -> tuple[tuple[int, int, int, int], str]:
    a, b = draw(st.integers(0, 7)), draw(st.integers(0, 24))
    c, d = draw(st.integers(a, 8)), draw(st.integers(0, 24))
    if c == a:
        d = max(b, d)
    return (a, b, c, d), draw(st.one_of(texts(), LINE_TEXTS, BREAKS))


@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
@given(start=texts(), changes=st.lists(edits(), min_size=1, max_size=5))
async def test_incremental_edits_agree_with_checking_the_whole_text(
        client: Client, start: str, changes: list[tuple[tuple[int, int, int, int], str]]
) -> None:
    uri, _ = await client.opened(start)
    model = start
    for version, (where, text) in enumerate(changes, start=2):
        client.change(uri, version, (where, text))
        low = utf16_offset(model, where[0], where[1])
        high = utf16_offset(model, where[2], where[3])
        model = model[:low] + text + model[high:]
    diagnostics = await client.diagnostics_of(uri, len(changes) + 1)
    assert published(diagnostics) == expected(model)
