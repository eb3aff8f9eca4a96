"""Code past line 65535 with the debug section (E0191) is known from the text: a compile
reports it before parsing (source.first_code_line_after), so that 8 MiB of `A=1` is
refused at once instead of after gigabytes of syntax trees."""

from __future__ import annotations

import pytest

from rl1.compiler import analysis
from rl1.compiler.backend.driver import compile_text
from rl1.vm import ilc


def _refuse_checking(text: str, each_line: object) -> None:  # a compile's check parses
    raise AssertionError("the text was checked")


def test_code_past_line_65535_is_refused_before_parsing(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(analysis, "check_text", _refuse_checking)
    text = "' a long program\n" + "\n" * (ilc.MAX_LINE - 1) + "  ' more\n" + "A=1\n" * 100_000
    compilation = compile_text(text, "long.rob")
    assert compilation.output is None
    [diagnostic] = compilation.diagnostics
    assert diagnostic.code == "E0191" and diagnostic.span.line == ilc.MAX_LINE + 2
    with pytest.raises(AssertionError, match="the text was checked"):
        compile_text(text, "long.rob", strip_debug=True)  # no limit on lines: parsed


def test_blank_and_comment_lines_past_65535_are_not_refused() -> None:
    text = "(END)\n" + "' the end\n\n" * ilc.MAX_LINE
    compilation = compile_text(text, "padded.rob")
    assert compilation.output is not None, compilation.diagnostics
