"""How a message or a code snippet shows a character that a terminal would not: by its
code point, `U+00A0`, which the parser's E0102 names and the human report's snippets
show in its place (`<U+E000>`)."""

from __future__ import annotations

import unicodedata

# The categories of characters a terminal shows as nothing: controls, format characters
# (bidi overrides), private-use and unassigned code points, surrogates, line and
# paragraph separators.
BLANK = frozenset({"Cc", "Cf", "Co", "Cn", "Cs", "Zl", "Zp"})
# And those that, quoted alone, read as a space or join the quote: spaces, combining
# marks (in a line of text they show, as a gap or on the letter before them).
UNSEEN_ALONE = BLANK | {"Zs", "Mn", "Me"}


def code_point(character: str) -> str:
    """`U+00A0`: the name of `character` where it cannot be shown."""
    return f"U+{ord(character):04X}"


def shows_nothing(character: str) -> bool:
    """Whether a terminal would show `character` as nothing at all."""
    return unicodedata.category(character) in BLANK
