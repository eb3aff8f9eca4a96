"""Suppression comments (spec/language.md, section 2.5): `' rl1: allow W0601` silences a
warning on its own line, `' rl1: allow-file W0601` in the whole file.

Only warnings can be allowed: an error stops compilation whatever a comment says. A
directive that names no warning, or allows a warning that is not there, is itself
reported (W0107), so that a misspelt code or a stale comment does not linger unseen.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable, Sequence
from typing import NamedTuple

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity

MARK = "rl1:"
"""What a comment holds when it may be a directive: the quick test of every comment."""

KINDS = ("allow", "allow-file")


@functools.cache
def _patterns() -> tuple[re.Pattern[str], re.Pattern[str], re.Pattern[str]]:
    """The directive, a word shaped as a code, and a code; compiled when a comment first
    holds `rl1:` (most programs have none, and every start of rl1c would pay)."""
    return (re.compile(r"(?:^|(?<=\s))rl1:[ \t]*(?P<kind>[\w-]*)(?P<codes>.*)"),
            re.compile(r"[ \t,]*(?P<word>[A-Za-z][0-9]+)(?![\w-])"),
            # The catalogue is the reporting layer's; the checker knows a code's severity
            # from its letter, which the catalogue's tests hold to every code.
            re.compile(r"[EW][0-9]{4}"))


class Directive(NamedTuple):
    """One `rl1: allow` comment: its kind, the codes it names (as written, with their
    spans) and where it is."""

    file_wide: bool
    codes: tuple[tuple[str, ast.Span], ...]
    span: ast.Span

    @property
    def line(self) -> int:
        return self.span.line


def apply_suppressions(program: ast.Program, diagnostics: Iterable[Diagnostic], *,
                       complete: bool = True) -> list[Diagnostic]:
    """`diagnostics` without the warnings that the program's comments allow, with a
    W0107 for each directive, or code in one, that allows nothing. When `diagnostics`
    are not `complete` (a rule failed), a code they lack is not said to be unused."""
    return suppressed(program.lines, diagnostics, complete=complete)


def suppressed(lines: Sequence[ast.Line], diagnostics: Iterable[Diagnostic], *,
               complete: bool = True) -> list[Diagnostic]:
    """`apply_suppressions` given the program's lines, or only those whose comments
    hold MARK (streaming.py keeps only those)."""
    suppressions = Suppressions(lines)
    if suppressions.empty:
        return list(diagnostics)
    kept = [d for d in diagnostics if suppressions.reports(d.code, d.severity, d.span.line)]
    return kept + suppressions.problems(complete=complete)


class Suppressions:
    """The directives of a program's lines: which warnings they allow (noting each
    directive's codes that allowed one), and then the W0107s of those that allowed
    nothing. The streaming check asks it of each diagnostic's code, severity and line,
    without the diagnostic (checker/compact.py keeps none)."""

    def __init__(self, lines: Sequence[ast.Line]) -> None:
        self._directives, self._problems = _directives(lines)
        self._file_wide = {code for d in self._directives if d.file_wide
                           for code, _ in d.codes}
        self._on_line: dict[int, set[str]] = {}
        for directive in self._directives:
            if not directive.file_wide:
                self._on_line.setdefault(directive.line, set()).update(
                    code for code, _ in directive.codes)
        self._used: set[tuple[int | None, str]] = set()  # (line, code); None: the file

    @property
    def empty(self) -> bool:
        """No directive, and nothing to say of one: every diagnostic is reported."""
        return not self._directives and not self._problems

    def reports(self, code: str, severity: Severity, line: int) -> bool:
        """Whether a diagnostic `code` of `severity` on `line` is reported: no directive
        allows it (only warnings can be allowed); a directive that does is noted."""
        if severity is not Severity.WARNING:
            return True
        if code in self._on_line.get(line, ()):
            self._used.add((line, code))
        elif code in self._file_wide:
            self._used.add((None, code))
        else:
            return True
        return False

    def problems(self, *, complete: bool = True) -> list[Diagnostic]:
        """The W0107s: a directive that is none or names no warning code, and (when the
        diagnostics `reports` was asked of are `complete`) a code that allowed nothing."""
        problems = list(self._problems)
        for directive in self._directives if complete else ():
            scope = None if directive.file_wide else directive.line
            for code, span in directive.codes:
                if (scope, code) not in self._used:
                    where = "in this file" if directive.file_wide else "on this line"
                    problems.append(_unused(f"no {code} is reported {where}", span))
        return problems


def _directives(lines: Sequence[ast.Line]) -> tuple[list[Directive], list[Diagnostic]]:
    directives: list[Directive] = []
    problems: list[Diagnostic] = []
    for line in lines:
        comment = line.comment
        if comment is None or MARK not in comment.text:
            continue
        directive, code_shaped, _ = _patterns()
        match = directive.search(comment.text)
        if match is None:
            continue
        whole = _span(comment, match.start(), match.end("kind"))
        kind = match["kind"]
        if kind not in KINDS:
            problems.append(_unused(
                f"`rl1: {kind}` is not a directive: write `rl1: allow CODE` for this line "
                "or `rl1: allow-file CODE` for the whole file", whole))
            continue
        codes: list[tuple[str, ast.Span]] = []
        position = match.start("codes")
        while shaped := code_shaped.match(comment.text, position):
            word, position = shaped["word"], shaped.end()
            code_span = _span(comment, shaped.start("word"), shaped.end("word"))
            problem = _code_problem(word.upper())
            if problem is None:
                codes.append((word.upper(), code_span))
            else:
                problems.append(_unused(problem, code_span))
        if codes:
            directives.append(Directive(kind == "allow-file", tuple(codes), whole))
        elif position == match.start("codes"):
            problems.append(_unused(f"`rl1: {kind}` names no code: write the warning's code "
                                    f"after it, as in `rl1: {kind} W0601`", whole))
    return directives, problems


def _span(comment: ast.Comment, first: int, last: int) -> ast.Span:
    """The span of the comment's text from index `first` to `last`; the text starts one
    column after the quote."""
    start = comment.span.column + 1
    return ast.Span(comment.span.row, start + first, comment.span.row, start + last)


def _code_problem(code: str) -> str | None:
    if not _patterns()[2].fullmatch(code):
        return f"`{code}` is not a diagnostic code (`rl1c explain --list` lists them)"
    if code.startswith("E"):
        return f"`{code}` is an error, and errors cannot be allowed: fix the program"
    return None


def _unused(why: str, span: ast.Span) -> Diagnostic:
    return Diagnostic("W0107", Severity.WARNING,
                      f"this suppression comment allows nothing: {why}", span,
                      help="an `rl1: allow` comment names warning codes, such as W0601, that "
                           "are reported on its line (`rl1: allow-file`: in its file)")
