"""The catalogue of diagnostic codes: each code's severity, title and long explanation.

Codes are stable: never reuse or renumber one. Ranges by area:
E01xx source and syntax · E02xx/W02xx labels · E03xx/W03xx tracing handlers ·
W04xx reserved variables · E05xx/W05xx calls and constants · W06xx control flow ·
W07xx safety · E10xx run-time faults (not the checker's: the faults of a run, whose
last two digits are the exit status of `rl1c run`; vm/faults.py names each kind's code).
The long explanation of CODE is explanations/CODE.md, printed by `rl1c explain CODE`.
"""

from __future__ import annotations

import os
from typing import NamedTuple

from rl1.compiler.frontend.diagnostics import Severity

_EXPLANATIONS = os.path.join(os.path.dirname(__file__), "explanations")


class CodeInfo(NamedTuple):
    code: str
    severity: Severity
    title: str

    def explanation(self) -> str:
        with open(os.path.join(_EXPLANATIONS, f"{self.code}.md"), encoding="utf-8") as file:
            return file.read()


def _entries(*rows: tuple[str, Severity, str]) -> dict[str, CodeInfo]:
    return {code: CodeInfo(code, severity, title) for code, severity, title in rows}


E, W = Severity.ERROR, Severity.WARNING

CODES: dict[str, CodeInfo] = _entries(
    ("E0100", E, "a file cannot be read, written or used"),
    ("E0101", E, "syntax error"),
    ("E0102", E, "unexpected character"),
    ("E0103", E, "a word that is not a variable"),
    ("E0104", E, "label not at the start of a line"),
    ("E0105", E, "malformed hex constant"),
    ("E0106", E, "line too long"),
    ("W0107", W, "suppression comment that allows nothing"),
    ("E0190", E, "compiled code too large for .ilc"),
    ("E0191", E, "code past line 65535 with a debug section"),
    ("E0201", E, "label not exactly two digits"),
    ("E0202", E, "jump target not exactly two digits"),
    ("E0203", E, "jump to an undefined label"),
    ("E0204", E, "label defined twice"),
    ("W0205", W, "label never jumped to"),
    ("W0301", W, "missing lost-line handler"),
    ("W0401", W, "reserved variable read before a call sets it"),
    ("W0402", W, "assignment to a reserved variable"),
    ("E0501", E, "unknown built-in function"),
    ("W0502", W, "built-in name or selector not in upper case"),
    ("E0503", E, "wrong number of arguments"),
    ("E0504", E, "argument of the wrong kind"),
    ("E0505", E, "unknown selector"),
    ("E0506", E, "constant out of the parameter's range"),
    ("E0507", E, "decimal constant does not fit in 16 bits"),
    ("E0508", E, "call without a result used as an operand"),
    ("W0601", W, "unreachable code"),
    ("W0602", W, "code after (END)"),
    ("W0603", W, "program without (END)"),
    ("W0604", W, "busy loop that never observes the world"),
    ("W0701", W, "program may end while the vehicle moves"),
    ("E1010", E, "run-time fault: argument out of range"),
    ("E1011", E, "run-time fault: missing lost-line handler"),
    ("E1012", E, "run-time fault: budget exhausted"),
    ("E1013", E, "run-time fault: device error"),
    ("E1014", E, "run-time fault: aborted"),
)
