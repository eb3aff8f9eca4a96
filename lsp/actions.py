"""Code actions: the checker's fixes as quick fixes, a comment that allows a warning on
its line, and the safe fixes at once as `source.fixAll`, which `rl1c check --fix` makes
(both through `analysis.fix`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from lsprotocol import types

from rl1.compiler.analysis import fix as fix_text
from rl1.compiler.checker.suppression import MARK
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Edit, Fix, Severity
from rl1.compiler.frontend.edits import apply_edits
from rl1.compiler.frontend.source import LINE_BREAK
from rl1.compiler.reporting.selection import Selection

from .checking import to_lsp
from .document import Document
from .positions import Columns
from .project import ProjectFiles

# The rl1.toml selections that decide which fixes "fix all" makes, as for the checks.
_PROJECTS = ProjectFiles()
FIX_ALL = "Apply every safe fix (as `rl1c check --fix`)"


def fix_edit(document: Document, fix: Fix, columns: Columns) -> types.WorkspaceEdit:
    """The fix as one edit, whose text is what `rl1c check --fix` writes there
    (apply_edits), not the fix's edits as given, which an editor would make otherwise:
    apply_edits writes a line break in an edit's text as the document's first line end,
    and keeps a line it empties between a lone CR and an LF apart, where the two would
    join. The edits are made in the lines around them only: from the line before the
    first (apply_edits looks at its end) to the line after the last (whose start it
    looks at, and may take in)."""
    first = max(min(min(edit.span.line for edit in fix.edits), document.line_count) - 1, 1)
    last = min(max(edit.span.end_line for edit in fix.edits) + 1, document.line_count)
    before = document.text_of_lines(first, last)
    lead, moved = "", 0  # what goes before the lines, and how many lines up they move
    if first > 1:
        # After a line that ends as the document's first (the line end apply_edits
        # writes), and a character that keeps that end from joining an LF they start
        # with: line `first` is the second, and the edits fall after it.
        lead, moved = document.line_end(1) + "x", first - 2
    after = apply_edits(lead + before, [
        Edit(ast.Span(edit.span.line - moved, edit.span.column,
                      edit.span.end_line - moved, edit.span.end_column), edit.text)
        for edit in fix.edits])[len(lead):]
    start, end, text = _difference(before, after)
    span = ast.Span(*_place(before, start, first), *_place(before, end, first))
    return types.WorkspaceEdit(changes={document.uri: [
        types.TextEdit(range=document.range_of(span, columns), new_text=text)]})


def _difference(before: str, after: str) -> tuple[int, int, str]:
    """Where `after` differs from `before`: the start and end in `before` of what lies
    between the text both start with and the text both end with, and what `after` has
    there; neither end between a CR and an LF, where LSP has no position."""
    start, alike = 0, min(len(before), len(after))
    while start < alike and before[start] == after[start]:
        start += 1
    if start > 0 and before[start - 1 : start + 1] == "\r\n":
        start -= 1
    same_end = 0
    while same_end < alike - start and before[-1 - same_end] == after[-1 - same_end]:
        same_end += 1
    end = len(before) - same_end
    if end < len(before) and before[end - 1 : end + 1] == "\r\n":
        end, same_end = end + 1, same_end - 1
    return start, end, after[start : len(after) - same_end]


def _place(text: str, offset: int, first: int) -> tuple[int, int]:
    """The 1-based line and column of `offset` in `text`, which starts at line `first`."""
    breaks = list(LINE_BREAK.finditer(text, 0, offset))
    return first + len(breaks), offset - (breaks[-1].end() if breaks else 0) + 1


def _on_lines(diagnostic: Diagnostic, first: int, last: int) -> bool:
    """Whether the diagnostic shares a line with the request: a cursor anywhere on the
    line of a problem is offered its fix."""
    return diagnostic.span.line <= last and first <= diagnostic.span.end_line


def code_actions(document: Document, diagnostics: list[Diagnostic], requested: types.Range,
                 only: Sequence[str] | None, columns: Columns,
                 resolves_edits: bool = False) -> list[types.CodeAction]:
    """Quick fixes for the diagnostics in `requested`, then one fix-all action, whose
    edit is left for `codeAction/resolve` when the client `resolves_edits` (it costs a
    check of the program for each round of fixes, and editors ask for code actions
    whenever the cursor moves)."""
    first = document.locate(requested.start, columns)[0]
    last = document.locate(requested.end, columns)[0]
    actions: list[types.CodeAction] = []
    if only is None or any(kind.startswith("quickfix") for kind in only):
        for diagnostic in diagnostics:
            if not _on_lines(diagnostic, first, last):
                continue
            for fix in diagnostic.fixes:
                actions.append(types.CodeAction(
                    title=fix.title,
                    kind=types.CodeActionKind.QuickFix,
                    diagnostics=[to_lsp(diagnostic, document, columns)],
                    edit=fix_edit(document, fix, columns),
                    # An editor may make a preferred fix unasked: only a safe one.
                    is_preferred=len(diagnostic.fixes) == 1 and fix.safe,
                ))
            allow = _allow(document, diagnostic)
            if allow is not None:
                actions.append(types.CodeAction(
                    title=allow.title, kind=types.CodeActionKind.QuickFix,
                    diagnostics=[to_lsp(diagnostic, document, columns)],
                    edit=fix_edit(document, allow, columns)))
    wants_fix_all = only is None or any(types.CodeActionKind.SourceFixAll.startswith(kind)
                                        for kind in only)
    if wants_fix_all and any(one.safe for diagnostic in diagnostics for one in diagnostic.fixes):
        fix_all = types.CodeAction(title=FIX_ALL, kind=types.CodeActionKind.SourceFixAll,
                                   data={"uri": document.uri, "version": document.version})
        if not resolves_edits:
            fix_all.edit = _fix_all_edit(document, columns)
        if fix_all.edit is not None or resolves_edits:
            actions.append(fix_all)
    return actions


def resolve(action: types.CodeAction, open_document: Callable[[str], Document | None],
            columns: Columns) -> types.CodeAction:
    """The fix-all action with its edit, for the version of the document it was offered
    for; any other action, or one for a version since changed, as it came (no edit)."""
    data = action.data if isinstance(action.data, dict) else {}
    document = open_document(data["uri"]) if isinstance(data.get("uri"), str) else None
    if action.kind == types.CodeActionKind.SourceFixAll and document is not None \
            and data.get("version") == document.version:
        action.edit = _fix_all_edit(document, columns)
    return action


def _allow(document: Document, diagnostic: Diagnostic) -> Fix | None:
    """A comment that allows a warning on its line (spec/language.md, 2.5), when the
    line has no directive yet (only a comment's first one counts)."""
    number = diagnostic.span.line
    if diagnostic.severity is not Severity.WARNING or diagnostic.code == "W0107" \
            or not 1 <= number <= document.line_count:
        return None
    comment = document.line(number).comment
    if comment is not None and MARK in comment.text:
        return None
    end = len(document.line_text(number)) + 1
    lead = " " if comment is not None else " ' "  # into the comment, or a new one
    return Fix(f"Allow {diagnostic.code} on this line (a `rl1: allow` comment)",
               (Edit(ast.Span(number, end, number, end),
                     f"{lead}rl1: allow {diagnostic.code}"),))


def _fix_all_edit(document: Document, columns: Columns) -> types.WorkspaceEdit | None:
    """The safe fixes, made as `rl1c check --fix` makes them, as one edit of the lines
    they change; None when they change nothing."""
    selection = _PROJECTS.selection(document.uri)
    if not isinstance(selection, Selection):  # a broken rl1.toml: as the checks do
        selection = Selection()
    before = document.text()
    fixed = document.derived(_fixed_texts)
    if selection not in fixed:  # once per version and selection
        fixed[selection] = fix_text(before, selection.reports).text
    after = fixed[selection]
    if after == before:
        return None
    return types.WorkspaceEdit(changes={document.uri: [
        _changed_lines(document, before, after, columns)]})


def _fixed_texts(document: Document) -> dict[Selection, str]:
    """The document's text with its safe fixes made, by selection (filled as asked)."""
    return {}


def _changed_lines(document: Document, before: str, after: str,
                   columns: Columns) -> types.TextEdit:
    """One edit that turns `before` (the document's text) into `after`: the lines from
    the first that differs to the last that differs, with their line ends."""
    old, new = _with_ends(before), _with_ends(after)
    same_start = 0
    while same_start < min(len(old), len(new)) and old[same_start] == new[same_start]:
        same_start += 1
    same_end = 0
    while same_end < min(len(old), len(new)) - same_start \
            and old[-1 - same_end] == new[-1 - same_end]:
        same_end += 1

    def start_of(index: int) -> types.Position:
        # Past the last line: the document's end (after its last line end, if any).
        ends_in_break = bool(old) and LINE_BREAK.search(old[-1]) is not None
        if index < len(old) or ends_in_break or not old:
            return types.Position(index, 0)
        return document.end_position(columns)

    return types.TextEdit(
        range=types.Range(start_of(same_start), start_of(len(old) - same_end)),
        new_text="".join(new[same_start:len(new) - same_end]))


def _with_ends(text: str) -> list[str]:
    """The lines of `text`, each with its line end (the last one may have none)."""
    starts = [0, *(found.end() for found in LINE_BREAK.finditer(text))]
    return [line for line in (text[a:b] for a, b in zip(starts, [*starts[1:], len(text)],
                                                        strict=True)) if line]
