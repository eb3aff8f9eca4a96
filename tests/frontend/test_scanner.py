"""The scanner against section 3 of the spec, read literally.

The reference below follows the spec's wording step by step: at each position the first
alternative of the table in 3.1 that matches, then the three context rules of 3.2, then
3.3's test of a hex constant. compiler/frontend/scanner.py gets there faster (one `findall`,
kinds decided by the first character); both must cut every line the same way.
"""

from __future__ import annotations

import re

from hypothesis import given, settings
from hypothesis import strategies as st

from rl1.compiler.frontend.scanner import WHITESPACE, Kinds, Lexeme, scan
from rl1.compiler.strategies import lines

_TABLE_3_1 = re.compile(r"""
     (?P<space>[ \t\f\v]+)
    |(?P<LABEL>:[0-9]*)
    |(?P<LABELREF>\#[0-9]*)
    |(?P<NUMBER>-?[0-9]+)
    |(?P<HEX>\$[0-9A-Za-z]*)
    |(?P<word>[A-Za-z@][A-Za-z0-9@]*)
    |(?P<INCDEC>\+\+|--(?![0-9]))
    |(?P<OPERATOR>[-+&|^])
    |(?P<punctuation>[<>=?(),;])
""", re.VERBOSE)
_PUNCTUATION = {"<": "LESS", ">": "MORE", "=": "EQUAL", "?": "QMARK", "(": "LPAR",
                ")": "RPAR", ",": "_COMMA", ";": "_SEMI"}


def _reference_scan(code: str) -> tuple[Kinds, list[Lexeme]]:
    tokens: list[tuple[str, str, int]] = []
    position = 0
    while position < len(code):
        found = _TABLE_3_1.match(code, position)
        if found is None:  # 3.1: any other character is an error token of its own
            tokens.append(("BAD", code[position], position))
            position += 1
            continue
        kind, text, position = found.lastgroup or "", found.group(), found.end()
        start = found.start()
        previous = tokens[-1][0] if tokens else ""
        if kind == "space":
            continue
        if kind == "punctuation":
            kind = _PUNCTUATION[text]
        elif kind == "word":  # 3.2, rule 1
            kind = "MNEMONIC" if previous == "LPAR" else "VAR" if len(text) == 1 else "WORD"
        elif kind == "NUMBER" and text.startswith("-") and previous in (
                "VAR", "NUMBER", "HEX", "RPAR"):  # 3.2, rule 2
            tokens.append(("OPERATOR", "-", start))
            kind, text, start = "NUMBER", text[1:], start + 1
        elif kind == "HEX":  # 3.3
            digits = text[1:]
            if not (re.fullmatch("[0-9A-Fa-f]+", digits) and int(digits, 16) <= 0xFFFF):
                kind = "BADHEX"
        tokens.append((kind, text, start))
    return tuple(kind for kind, _, _ in tokens), [(text, start) for _, text, start in tokens]


_PIECES = ["A", "ab", "@", "=", "+", "-", "--", "++", "&", "|", "^", "<", ">", "?", "(", ")",
           ",", ";", "MOV", "0", "12", "-3", "$", "$F", "$0FFFF", "$10000", "$G", "$0x1",
           ":", ":1", "#", "#99", "．", "\u3000", "é", *WHITESPACE]


@settings(max_examples=500, deadline=None)
@given(st.one_of(st.lists(st.sampled_from(_PIECES), max_size=16).map("".join),
                 lines().map(lambda line: line.partition("'")[0]),
                 st.text(max_size=30)))
def test_the_scanner_cuts_lines_as_the_spec_says(code: str) -> None:
    assert scan(code) == _reference_scan(code)


def test_context_rules_by_example() -> None:
    assert scan("A=B--5")[0] == ("VAR", "EQUAL", "VAR", "OPERATOR", "NUMBER")
    assert scan("(x)")[0] == ("LPAR", "MNEMONIC", "RPAR")
    assert scan("A=$00FFFF")[0][-1] == "HEX"
    assert scan("A=$1FFFF")[0][-1] == "BADHEX"
