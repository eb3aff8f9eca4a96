"""The report written a diagnostic at a time (issue 23, item 10) is the very text of the
report built whole, as it was before: the reference below is that way, kept to hold the
streamed one to it in every format, on generated sources and on a large one."""

from __future__ import annotations

import io
import json
from collections.abc import Sequence

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rl1.compiler import analysis
from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity, sort_key
from rl1.compiler.reporting.catalogue import CODES
from rl1.compiler.reporting.render import (
    FORMATS,
    SARIF_SCHEMA,
    FileDiagnostics,
    Format,
    _HumanRenderer,
    _json_item,
    _sarif_result,
    _sarif_rule,
    _tool_version,
    concise_line,
    report,
    write_report,
)


def whole_report(files: Sequence[FileDiagnostics], output_format: Format, color: bool,
                 action: str | None) -> str:
    """The report as one string, built as render.report built it before it streamed."""
    if output_format == "json":
        items = [_json_item(file, d) for file in files
                 for d in sorted(file.diagnostics, key=sort_key)]
        return json.dumps(items, indent=2, ensure_ascii=True) + "\n"
    if output_format == "sarif":
        rule_index = {code: index for index, code in enumerate(CODES)}
        log = {"$schema": SARIF_SCHEMA, "version": "2.1.0", "runs": [{
            "tool": {"driver": {"name": "rl1c", "version": _tool_version(),
                                "rules": [_sarif_rule(code) for code in CODES]}},
            "columnKind": "unicodeCodePoints",
            "results": [_sarif_result(file, d, rule_index) for file in files
                        for d in sorted(file.diagnostics, key=sort_key)],
        }]}
        return json.dumps(log, indent=2, ensure_ascii=True) + "\n"
    if output_format == "concise":
        return "".join(concise_line(file, d) for file in files
                       for d in sorted(file.diagnostics, key=sort_key))
    texts = []
    for file in files:
        renderer = _HumanRenderer(file, color)
        blocks = [renderer.diagnostic(d) for d in sorted(file.diagnostics, key=sort_key)]
        if action is not None:
            blocks.append(renderer.summary(action))
        texts.append("".join(blocks))
    return ("" if action is None else "\n").join(text for text in texts if text)


PIECES = ["A=1", "B=2", "A=1 B=2", "(MOV 1,1)", ":10", "#10", "(END)", "X=", "#99", "",
          "' rl1: allow W0601", "\t\u00e9\u4e2d", "(TIM 100)", "A=A+1;B=A", "\x1b[31m",
          "(MOV 3,3)", "A=1;" * 40, "'\u202e comment", "\"text"]
sources = st.lists(st.sampled_from(PIECES), max_size=12).map("\n".join)
names = st.sampled_from(["prog.rob", "/abs/x.rob", "d\u00e9/\u4e2d p.rob", "a\x1bb.rob"])


def checked(name: str, text: str | None) -> FileDiagnostics:
    if text is None:  # a file that could not be read: its E0100
        return FileDiagnostics(name, None, [Diagnostic(
            "E0100", Severity.ERROR, f"cannot read `{name}`", Span(1, 0, 1, 0))])
    return FileDiagnostics(name, text, analysis.diagnose(text))


@settings(max_examples=150, deadline=None)
@given(files=st.lists(st.tuples(names, st.none() | sources), max_size=3),
       output_format=st.sampled_from(FORMATS), color=st.booleans(),
       action=st.sampled_from(["check", None]))
def test_the_streamed_report_is_the_whole_one(files: list[tuple[str, str | None]],
                                              output_format: Format, color: bool,
                                              action: str | None) -> None:
    reported = [checked(name, text) for name, text in files]
    assert (report(reported, output_format, color=color, action=action)
            == whole_report(reported, output_format, color, action))


class Recording(io.StringIO):
    """A stream that keeps the length of each write."""

    def __init__(self) -> None:
        super().__init__()
        self.writes: list[int] = []

    def write(self, text: str) -> int:
        self.writes.append(len(text))
        return super().write(text)


@pytest.mark.parametrize("output_format", FORMATS)
def test_a_large_report_is_the_whole_one_written_a_diagnostic_at_a_time(
        output_format: Format) -> None:
    text = "A=1 B=2\n(MOV 3,3)\n" * 3000 + "X=\n:10\n#10\n"
    files = [checked("big.rob", text), checked("other.rob", "#20\n"),
             checked("gone.rob", None)]
    stream = Recording()
    write_report(stream, files, output_format, action="check")
    assert stream.getvalue() == whole_report(files, output_format, False, "check")
    diagnostics = sum(len(file.diagnostics) for file in files)
    assert len(stream.writes) >= diagnostics > 3000
    # No write holds more than a few diagnostics (SARIF's first holds its rules).
    assert sorted(stream.writes)[-2] < 2000
