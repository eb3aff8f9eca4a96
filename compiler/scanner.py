"""The scanner: one line of RL/I code (comment already removed) to tokens.

Hand-written over one regular expression because it is the hot path (lark's own
contextual lexer is several times slower) and because three tokens depend on context:
- a word right after `(` is a MNEMONIC; elsewhere a single letter is a VAR and a longer
  word is a WORD, which the parser rejects with a helpful message;
- `-` followed by digits is part of a NUMBER unless it follows an operand (`B-5`);
- `--` is the decrement INCDEC unless a digit follows (`A=B--5` is `B - -5`).
"""

from __future__ import annotations

import re
from collections.abc import Iterator

WHITESPACE = " \t\f\v"
"""What separates tokens; any other character outside a comment, a full-width space
included, is an error."""

_TOKEN = re.compile(
    r"(?P<SPACE>[" + re.escape(WHITESPACE) + r"]+)" + r"""
    |(?P<LABEL>:[0-9]*)
    |(?P<LABELREF>\#[0-9]*)
    |(?P<NUMBER>-?[0-9]+)
    |(?P<HEX>\$[0-9A-Za-z]*)
    |(?P<WORD>[A-Za-z@][A-Za-z0-9@]*)
    |(?P<INCDEC>\+\+|--(?![0-9]))
    |(?P<PUNCT>[-+&|^<>=?(),;])
    """,
    re.VERBOSE,
)

PUNCTUATION = {
    "+": "PLUS", "-": "MINUS", "&": "AMP", "|": "BAR", "^": "CARET", "<": "LESS",
    ">": "MORE", "=": "EQUAL", "?": "QMARK", "(": "LPAR", ")": "RPAR", ",": "_COMMA",
    ";": "_SEMI",
}
_ENDS_OPERAND = frozenset({"VAR", "NUMBER", "HEX", "RPAR"})


class Token:
    """A token: its kind (a terminal of grammar.lark), its text and its 0-based column.
    Deliberately lighter than lark's Token: the scanner makes millions of them."""

    __slots__ = ("column", "text", "type")

    def __init__(self, kind: str, text: str, column: int) -> None:
        self.type = kind
        self.text = text
        self.column = column

    def __repr__(self) -> str:
        return f"Token({self.type}, {self.text!r}, {self.column})"


class ScanError(Exception):
    def __init__(self, column: int, character: str) -> None:
        super().__init__(f"unexpected character {character!r}")
        self.column = column  # 0-based
        self.character = character


def scan(code: str) -> Iterator[Token]:
    """Tokens of one line of code. Token positions are 0-based columns."""
    position = 0
    previous = ""
    match = _TOKEN.match
    length = len(code)
    while position < length:
        found = match(code, position)
        if found is None:
            raise ScanError(position, code[position])
        kind = found.lastgroup or ""
        text = found.group()
        position = found.end()
        if kind == "SPACE":
            continue
        start = found.start()
        if kind == "PUNCT":
            kind = PUNCTUATION[text]
        elif kind == "WORD":
            if previous == "LPAR":
                kind = "MNEMONIC"
            elif len(text) == 1:
                kind = "VAR"
        elif kind == "NUMBER" and text[0] == "-" and previous in _ENDS_OPERAND:
            yield Token("MINUS", "-", start)
            kind, text, start = "NUMBER", text[1:], start + 1
        previous = kind
        yield Token(kind, text, start)
