"""Making edits in source text: which fixes can be made together, and making them."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from .diagnostics import Edit, Fix
from .source import LINE_BREAK, LineIndex

_Place = tuple[int, int]  # (line, column)


def compatible(fixes: Iterable[Fix]) -> list[Fix]:
    """The fixes, in order, less any with an edit that overlaps, or inserts at the same
    place as, an edit of a fix kept before it: made together, they could not each do
    what it says (two lines added at the end would come in an order neither chose)."""
    taken: list[tuple[_Place, _Place]] = []
    kept: list[Fix] = []
    for fix in fixes:
        spans = [((e.span.line, e.span.column), (e.span.end_line, e.span.end_column))
                 for e in fix.edits]
        if any((start < t_end and t_start < end) or start == t_start
               for start, end in spans for t_start, t_end in taken):
            continue
        taken += spans
        kept.append(fix)
    return kept


def apply_edits(text: str, edits: Sequence[Edit]) -> str:
    """`text` with `edits`, which must not overlap, made. A line break in an edit's text
    is written as the text's first line end (LF if it has none), so that a file keeps
    its line ends; a place past the end of a line is its end."""
    first_break = LINE_BREAK.search(text)
    line_end = first_break.group() if first_break else "\n"
    lines = LineIndex(text)  # 8 bytes a line: `rl1c check --fix` of a long source

    def offset(line: int, column: int) -> int:
        if line > len(lines):
            return len(text)
        return lines.start(line - 1) + min(column - 1, len(lines[line - 1]))

    placed = sorted(((offset(e.span.line, e.span.column),
                      offset(e.span.end_line, e.span.end_column), e.text) for e in edits),
                    key=lambda item: item[0], reverse=True)
    for start, end, new in placed:
        text = text[:start] + new.replace("\n", line_end) + text[end:]
    return text
