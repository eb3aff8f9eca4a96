"""The editors' highlighting agrees with the compiler.

editors/vscode/test/expected/*.tokens record what VS Code's own TextMate engine makes of
Listing 1 and the edge cases (the extension's `npm test` keeps them true to the grammar).
Here every token the compiler's scanner finds must appear there at the same column,
with the same text and a scope of the matching class, so that highlighting splits every
line as the compiler does (`A=B--5` is B minus -5, `C--` a decrement). The editors'
lists of built-in functions must be the compiler's.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

import pytest
from support import ROOT

from rl1.compiler.frontend.scanner import scan
from rl1.vm.language import BUILTINS, HANDLER_LABELS, RESERVED_VARIABLES

EDITORS = ROOT / "editors"
EXPECTED = sorted((EDITORS / "vscode" / "test" / "expected").glob("*.tokens"))

_LINE_HEADER = re.compile(r"(\d+): (.*)")
_TOKEN = re.compile(r' +(\d+)  ("(?:[^"\\]|\\.)*") +(.*)')

# The scope class each of the scanner's token kinds is highlighted as, when the kind
# alone decides it.
_SCOPE_OF_KIND = {
    "NUMBER": "constant.numeric.decimal",
    "QMARK": "keyword.control.conditional",
    "LPAR": "punctuation.section.parens.begin",
    "RPAR": "punctuation.section.parens.end",
    "_SEMI": "punctuation.separator.statement",
    "_COMMA": "punctuation.separator.arguments",
    "WORD": "invalid.illegal",
    "BADHEX": "invalid.illegal.hex",
    "BAD": "invalid.illegal.character.rl1",
}
_OPERATOR_SCOPES = {"+": "keyword.operator.arithmetic", "-": "keyword.operator.arithmetic",
                    "&": "keyword.operator.bitwise", "|": "keyword.operator.bitwise",
                    "^": "keyword.operator.bitwise"}
_SELECTORS = {
    builtin.mnemonic: "".join(form.selector or "" for form in builtin.forms)
    for builtin in BUILTINS.values() if builtin.has_selector
}


@dataclass(frozen=True)
class Highlight:
    column: int  # 1-based
    text: str
    scopes: tuple[str, ...]


def read_tokens(path: Path) -> list[tuple[str, dict[int, Highlight]]]:
    """Each source line of an expectation file with its tokens by column."""
    lines: list[tuple[str, dict[int, Highlight]]] = []
    for row in path.read_text(encoding="utf-8").splitlines():
        if row.startswith("#"):
            continue
        if header := _LINE_HEADER.fullmatch(row):
            assert int(header[1]) == len(lines) + 1, f"{path.name}: line {header[1]} out of order"
            lines.append((header[2], {}))
        elif token := _TOKEN.fullmatch(row):
            column = int(token[1])
            scopes = () if token[3] == "-" else tuple(token[3].split())
            lines[-1][1][column] = Highlight(column, json.loads(token[2]), scopes)
        else:
            raise AssertionError(f"{path.name}: unreadable line {row!r}")
    return lines


def expected_class(kind: str, text: str, before: list[tuple[str, str]]) -> str:
    """The scope class the compiler's reading of a token calls for; `before` holds the
    kinds and texts of the tokens before it on its line."""
    previous = before[-1] if before else ("", "")
    if kind == "LABEL":
        if before or len(text) != 3:
            return "invalid.illegal.label"
        return ("entity.name.label.handler" if int(text[1:]) in HANDLER_LABELS
                else "entity.name.label")
    if kind == "LABELREF":
        return "keyword.control.goto" if len(text) == 3 else "invalid.illegal.jump-target"
    if kind == "MNEMONIC":
        return ("support.function.builtin" if text.upper() in BUILTINS
                else "invalid.illegal.unknown-function")
    if kind == "VAR":
        if previous[0] == "MNEMONIC" and previous[1].upper() in _SELECTORS:
            valid = text.upper() in _SELECTORS[previous[1].upper()]
            return "constant.language.selector" if valid else "invalid.illegal.selector"
        return "variable.language.reserved" if text in RESERVED_VARIABLES else "variable.other"
    if kind == "HEX":
        return "constant.numeric.hex"
    if kind == "OPERATOR":
        return _OPERATOR_SCOPES[text]
    if kind == "INCDEC":
        return "keyword.operator.increment" if text == "++" else "keyword.operator.decrement"
    if kind in ("EQUAL", "LESS", "MORE"):
        if len(before) >= 2 and before[-2][0] == "QMARK" and previous[0] == "VAR":
            return "keyword.operator.comparison"
        if kind == "EQUAL":
            return "keyword.operator.assignment"
        return "keyword.operator.bitwise.shift"
    return _SCOPE_OF_KIND[kind]


def test_there_are_expectation_files_for_the_sample_and_the_edge_cases() -> None:
    names = {path.stem for path in EXPECTED}
    assert {"sample", "expressions", "calls", "labels", "comments"} <= names


@pytest.mark.parametrize("path", EXPECTED, ids=lambda path: path.name)
def test_textmate_tokens_are_the_scanners_tokens(path: Path) -> None:
    for number, (line, highlights) in enumerate(read_tokens(path), start=1):
        code = line.partition("'")[0]
        where = f"{path.name} line {number} {line!r}"
        before: list[tuple[str, str]] = []
        kinds, lexemes = scan(code)
        for kind, (text, start) in zip(kinds, lexemes, strict=True):
            column = start + 1
            highlight = highlights.get(column)
            assert highlight is not None and highlight.text == text, (
                f"{where}: the scanner reads {text!r} at column {column}, "
                f"the grammar {highlight}"
            )
            wanted = expected_class(kind, text, before)
            assert any(scope.startswith(wanted) for scope in highlight.scopes), (
                f"{where}: {text!r} at column {column} should be {wanted}, "
                f"is {highlight.scopes}"
            )
            before.append((kind, text))


def test_comments_are_highlighted_to_the_end_of_the_line() -> None:
    for path in EXPECTED:
        for line, highlights in read_tokens(path):
            quote = line.find("'")
            if quote < 0:
                continue
            rest = [h for column, h in highlights.items() if column > quote]
            assert rest and all("comment.line.quote.rl1" in h.scopes for h in rest), line


def _textmate_mnemonics() -> set[str]:
    grammar = json.loads((EDITORS / "vscode" / "syntaxes" / "rl1.tmLanguage.json")
                         .read_text(encoding="utf-8"))
    calls = grammar["repository"]["call"]["patterns"]
    names: set[str] = set()
    for rule in calls:
        if rule["beginCaptures"]["2"]["name"] == "support.function.builtin.rl1":
            found = re.search(r"\(\?i:([A-Z|]+)\)", rule["begin"])
            assert found is not None, rule["begin"]
            names.update(found[1].split("|"))
    return names


def test_the_textmate_grammar_knows_exactly_the_builtins() -> None:
    assert _textmate_mnemonics() == set(BUILTINS)


def test_the_emacs_mode_knows_exactly_the_builtins() -> None:
    source = (EDITORS / "emacs" / "rl1-mode.el").read_text(encoding="utf-8")
    found = re.search(r"\(defconst rl1-mnemonics\s+'\(([^)]*)\)", source)
    assert found is not None
    assert set(re.findall(r'"([A-Z]+)"', found[1])) == set(BUILTINS)
