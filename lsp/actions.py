"""Code actions: the checker's fixes as quick fixes, a comment that allows a warning on
its line, and all the fixes at once as `source.fixAll`."""

from __future__ import annotations

from collections.abc import Sequence

from lsprotocol import types

from rl1.compiler.checker.suppression import MARK
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Edit, Fix, Severity
from rl1.compiler.frontend.edits import compatible

from .checking import to_lsp
from .document import Document
from .positions import Columns


def _edit(document: Document, fix: Fix, columns: Columns) -> types.WorkspaceEdit:
    return types.WorkspaceEdit(changes={document.uri: [
        types.TextEdit(range=document.range_of(edit.span, columns), new_text=edit.text)
        for edit in fix.edits
    ]})


def _on_lines(diagnostic: Diagnostic, first: int, last: int) -> bool:
    """Whether the diagnostic shares a line with the request: a cursor anywhere on the
    line of a problem is offered its fix."""
    return diagnostic.span.line <= last and first <= diagnostic.span.end_line


def code_actions(document: Document, diagnostics: list[Diagnostic], requested: types.Range,
                 only: Sequence[str] | None, columns: Columns) -> list[types.CodeAction]:
    """Quick fixes for the diagnostics in `requested`, then one fix-all action."""
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
                    edit=_edit(document, fix, columns),
                    is_preferred=len(diagnostic.fixes) == 1,
                ))
            allow = _allow(document, diagnostic)
            if allow is not None:
                actions.append(types.CodeAction(
                    title=allow.title, kind=types.CodeActionKind.QuickFix,
                    diagnostics=[to_lsp(diagnostic, document, columns)],
                    edit=_edit(document, allow, columns)))
    if only is None or any(types.CodeActionKind.SourceFixAll.startswith(kind) for kind in only):
        fix_all = _fix_all(diagnostics)
        if fix_all.edits:
            actions.append(types.CodeAction(
                title=fix_all.title, kind=types.CodeActionKind.SourceFixAll,
                edit=_edit(document, fix_all, columns)))
    return actions


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


def _fix_all(diagnostics: list[Diagnostic]) -> Fix:
    """The only fix of each diagnostic that has exactly one, skipping any whose edits
    overlap an earlier one's (an editor cannot apply overlapping edits)."""
    fixes = compatible(d.fixes[0] for d in diagnostics if len(d.fixes) == 1)
    return Fix("Apply every fix the checker suggests",
               tuple(edit for fix in fixes for edit in fix.edits))
