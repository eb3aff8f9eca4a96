"""Which diagnostics `rl1c check` reports, and how: `--select` and `--ignore` (codes or
their prefixes, warnings only), and warnings counted as errors. The command line and a
project's rl1.toml (project.py) set the same `Selection`; the command line wins.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import NamedTuple

from rl1.compiler.checker.compact import CompactDiagnostics
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity

from .catalogue import CODES

WARNING_CODES = tuple(code for code, info in CODES.items() if info.severity is Severity.WARNING)


class SelectionError(ValueError):
    """A code list that selects nothing a user can select; the message says why."""


class Selection(NamedTuple):
    """None: not set here (so another source, or the default, decides). `select` and
    `ignore` hold code prefixes: `W06` is every W06xx code, `W` every warning."""

    select: tuple[str, ...] | None = None
    ignore: tuple[str, ...] | None = None
    warnings_as_errors: bool | None = None

    def over(self, base: Selection) -> Selection:
        """This selection, with what it leaves unset taken from `base`."""
        return Selection(
            self.select if self.select is not None else base.select,
            self.ignore if self.ignore is not None else base.ignore,
            self.warnings_as_errors if self.warnings_as_errors is not None
            else base.warnings_as_errors)

    def reports(self, diagnostic: Diagnostic) -> bool:
        """Errors always; a warning when it is selected (every one by default) and not
        ignored (an ignored code stays ignored whatever selects it)."""
        return self.reports_kind(diagnostic.code, diagnostic.severity)

    def reports_kind(self, code: str, severity: Severity) -> bool:
        """`reports` of a diagnostic of `code` and `severity`."""
        if severity is not Severity.WARNING:
            return True
        selected = self.select is None or code.startswith(self.select)
        return selected and not (self.ignore and code.startswith(self.ignore))

    def apply(self, diagnostics: Iterable[Diagnostic]) -> list[Diagnostic]:
        """The diagnostics reported, warnings made errors if so asked."""
        kept = [d for d in diagnostics if self.reports(d)]
        if not self.warnings_as_errors:
            return kept
        return [d._replace(severity=Severity.ERROR)
                if d.severity is Severity.WARNING else d for d in kept]

    def apply_compact(self, diagnostics: CompactDiagnostics) -> CompactDiagnostics:
        """`apply` to diagnostics held compactly (checker/compact.py), none built."""
        return diagnostics.selected(self.reports_kind, bool(self.warnings_as_errors))


def parse_codes(words: Sequence[str]) -> tuple[str, ...]:
    """Code prefixes from `words`, each a code or a prefix of warning codes, and each
    possibly a comma-separated list (`W0601,W0205`); the case does not matter.
    SelectionError names the first that selects no warning."""
    codes: list[str] = []
    for word in words:
        for part in word.split(","):
            code = part.strip().upper()
            if not code:
                raise SelectionError(f"an empty code in `{word}`: separate codes with single "
                                     "commas, as in `W0601,W0205`")
            if not any(warning.startswith(code) for warning in WARNING_CODES):
                raise SelectionError(_no_warning(code))
            codes.append(code)
    return tuple(codes)


def _no_warning(code: str) -> str:
    if any(known.startswith(code) for known in CODES):
        return (f"`{code}` names only errors, which are always reported (an error stops "
                "compilation): select or ignore warnings, such as W0601 or W06")
    return (f"`{code}` is no diagnostic code nor the start of one (`rl1c explain --list` "
            "lists them)")
