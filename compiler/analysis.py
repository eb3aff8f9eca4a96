"""The front end in one call: source text to AST and sorted diagnostics (those the
program's comments allow left out), or to the diagnostics alone (`diagnose`); `fix`
makes the checker's fixes."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Iterator
from typing import NamedTuple

from .checker import apply_suppressions, check, check_text
from .checker.compact import CompactDiagnostics
from .frontend.ast import Program
from .frontend.diagnostics import Diagnostic, Fix, sort_key
from .frontend.edits import apply_edits, compatible
from .frontend.parser import parse_program


class Analysis(NamedTuple):
    program: Program
    diagnostics: list[Diagnostic]

    @property
    def has_errors(self) -> bool:
        return any(diagnostic.is_error for diagnostic in self.diagnostics)


def analyze(text: str) -> Analysis:
    program, diagnostics = parse_program(text)
    diagnostics.extend(check(program))
    diagnostics = apply_suppressions(program, diagnostics)
    diagnostics.sort(key=sort_key)
    return Analysis(program, diagnostics)


def diagnose(text: str) -> list[Diagnostic]:
    """`analyze(text).diagnostics`, without holding the tree (checker/streaming.py)."""
    return list(check_text(text))


def diagnose_compactly(text: str) -> CompactDiagnostics:
    """`diagnose(text)`, holding those of single lines as a few bytes each until they are
    read (checker/compact.py): for `rl1c check`, whose memory is then the text's."""
    return check_text(text)


MAX_FIX_ROUNDS = 10
"""Rounds of fixing before `fix` gives up: one fix can bring out another (an added
`(END)` that the vehicle reaches still moving), and fixes at one place wait a round."""


class Fixed(NamedTuple):
    """The text with the fixes made, how many were made, its diagnostics (held compactly,
    as `diagnose_compactly` gives them: neither a tree nor the diagnostics are held), and
    how many of the diagnostics `keep` accepts are left with a fix (without `unsafe`: an
    unsafe one; with it: one that would be made over an unsafe fix's result, in another
    run)."""

    text: str
    fixes: int
    diagnostics: CompactDiagnostics
    left: int


def fix(text: str, keep: Callable[[Diagnostic], bool] = lambda _: True, *,
        unsafe: bool = False) -> Fixed:
    """`text` with the fixes of the diagnostics `keep` accepts made, round after round,
    until none is left (or MAX_FIX_ROUNDS): the safe ones, and with `unsafe` the unsafe
    ones of the text as given. A fix is never made over the result of another in one
    run unless both are safe: the fixes of the first round are made on what the user
    wrote, a later round's only when they and every fix before them are safe. So an
    unsafe fix is judged on what was written (the E0201 fix writes `:05`, and W0205's
    removal of a label nobody jumps to must not be made on it), and an unsafe fix's
    consequences wait for another run. `rl1c check --fix` and the language server's
    "fix all" both make their fixes through this function."""
    diagnostics = diagnose_compactly(text)
    made = 0
    for done in range(MAX_FIX_ROUNDS):
        fixes = compatible(_fixes(diagnostics, keep, unsafe and done == 0))
        if not fixes:
            break
        text = apply_edits(text, [edit for one in fixes for edit in one.edits])
        made += len(fixes)
        diagnostics = diagnose_compactly(text)
        if not all(one.safe for one in fixes):
            break
    left = sum(1 for d in diagnostics if keep(d) and d.fixes)
    return Fixed(text, made, diagnostics, left)


def _fixes(diagnostics: Iterable[Diagnostic], keep: Callable[[Diagnostic], bool], unsafe: bool
           ) -> Iterator[Fix]:
    """The first fix that may be made of each diagnostic `keep` accepts."""
    for diagnostic in diagnostics:
        if keep(diagnostic):
            yield from itertools.islice((one for one in diagnostic.fixes
                                         if one.safe or unsafe), 1)
