"""The scanner: one line of RL/I code (comment already removed) to tokens.

Hand-written over one regular expression because it is the hot path. It never fails:
a character or a word that no rule can use still becomes a token, of a kind the grammar
has no place for (BAD, BADHEX, WORD), so the parser reports it in the same way as any
other token out of place.

Three kinds depend on context:
- a word right after `(` is a MNEMONIC; elsewhere a single letter is a VAR and a longer
  word is a WORD;
- `-` followed by digits is part of a NUMBER unless it follows an operand (`B-5`);
- `--` is the decrement INCDEC unless a digit follows (`A=B--5` is `B - -5`).
"""

from __future__ import annotations

import re

WHITESPACE = " \t\f\v"
"""What separates tokens; any other character outside a comment, a full-width space
included, is an error."""

Kinds = tuple[str, ...]
"""The kinds of a line's tokens: all that the parser's tables look at."""

Lexeme = tuple[str, int]
"""A token's text and its 0-based column."""

# Each match is the white space before a token, then the token. The alternatives, in
# order: LABEL, LABELREF, NUMBER, HEX, word, INCDEC, then any other single character.
_TOKEN = re.compile(
    f"([{re.escape(WHITESPACE)}]*)"
    r"(:[0-9]*|\#[0-9]*|-?[0-9]+|\$[0-9A-Za-z]*|[A-Za-z@][A-Za-z0-9@]*|\+\+|--(?![0-9])"
    f"|[^{re.escape(WHITESPACE)}])"
)
_VALID_HEX = re.compile(r"\$0*[0-9A-Fa-f]{1,4}")
"""A hex constant of at most 16 bits (leading zeros allowed)."""

# The kind of a token by its first character; the cases that need more than that are
# settled in `scan`.
_KIND_OF_FIRST = {
    **dict.fromkeys("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz@", "VAR"),
    **dict.fromkeys("0123456789", "NUMBER"),
    **dict.fromkeys("+-&|^", "OPERATOR"),
    ":": "LABEL", "#": "LABELREF", "$": "BADHEX", "<": "LESS", ">": "MORE", "=": "EQUAL",
    "?": "QMARK", "(": "LPAR", ")": "RPAR", ",": "_COMMA", ";": "_SEMI",
}
_ENDS_OPERAND = frozenset({"VAR", "NUMBER", "HEX", "RPAR"})


def scan(code: str) -> tuple[Kinds, list[Lexeme]]:
    """The kinds and the lexemes of one line's tokens, in order."""
    kinds: list[str] = []
    lexemes: list[Lexeme] = []
    kind_of_first = _KIND_OF_FIRST.get
    column = 0
    previous = ""
    for space, text in _TOKEN.findall(code):
        column += len(space)
        kind = kind_of_first(text[0], "BAD")
        if kind == "VAR":
            if previous == "LPAR":
                kind = "MNEMONIC"
            elif len(text) > 1:
                kind = "WORD"
        elif len(text) > 1 or kind == "BADHEX":
            if kind == "OPERATOR":  # `++`, `--` or `-` and digits
                if text[1] in "+-":
                    kind = "INCDEC"
                elif previous in _ENDS_OPERAND:
                    kinds.append("OPERATOR")
                    lexemes.append(("-", column))
                    column += 1
                    text = text[1:]
                    kind = "NUMBER"
                else:
                    kind = "NUMBER"
            elif kind == "BADHEX" and _VALID_HEX.fullmatch(text):
                kind = "HEX"
        previous = kind
        kinds.append(kind)
        lexemes.append((text, column))
        column += len(text)
    return tuple(kinds), lexemes
