"""Making edits in source text: which fixes can be made together, and making them."""

from __future__ import annotations

import bisect
import itertools
from collections.abc import Iterable, Iterator, Sequence

from .diagnostics import Edit, Fix
from .source import LINE_BREAK, LineIndex

_Place = tuple[int, int]  # (line, column)


def compatible(fixes: Iterable[Fix]) -> Iterator[Fix]:
    """The fixes, in order, less any with an edit that overlaps, or inserts at the same
    place as, an edit of a fix kept before it: made together, they could not each do
    what it says (two lines added at the end would come in an order neither chose).
    Each is given as soon as it is kept, so that `rl1c check --fix` can hold them
    compactly (analysis.fix), where a list of them held 290 bytes a fix.

    The kept edits meet none of the others, so each is looked for by bisection among
    them, sorted: a source with a fix on each line has hundreds of thousands. (A fix
    whose own edits meet, or end before they start, would break that order: from it
    on, every kept edit is looked at.)"""
    starts: list[_Place] = []  # the kept edits' spans, sorted, as their starts and ends
    ends: list[_Place] = []
    apart = True  # whether the kept edits are in order and meet none of the others
    for fix in fixes:
        spans = [((e.span.line, e.span.column), (e.span.end_line, e.span.end_column))
                 for e in fix.edits]
        if any(_meets_one(span, starts, ends) if apart and span[0] <= span[1]
               else any(_meet(span, taken) for taken in zip(starts, ends, strict=True))
               for span in spans):
            continue
        apart = apart and all(start <= end for start, end in spans) and not any(
            _meet(one, other) for index, one in enumerate(spans) for other in spans[:index])
        for start, end in spans:
            index = bisect.bisect_left(starts, start)
            starts.insert(index, start)
            ends.insert(index, end)
        yield fix


def _meet(span: tuple[_Place, _Place], other: tuple[_Place, _Place]) -> bool:
    """Whether two edits' spans overlap or start at the same place."""
    (start, end), (other_start, other_end) = span, other
    return (start < other_end and other_start < end) or start == other_start


def _meets_one(span: tuple[_Place, _Place], starts: list[_Place], ends: list[_Place]
               ) -> bool:
    """`_meet` of `span` (which ends where or after it starts) and any of the spans given
    by their sorted starts and ends, which are in order and meet none of the others:
    only its neighbours may meet it."""
    start, end = span
    index = bisect.bisect_left(starts, start)
    if index < len(starts) and (starts[index] == start or starts[index] < end):
        return True
    return index > 0 and start < ends[index - 1]


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

    placed = _lines_kept_apart(text, sorted(
        ((offset(e.span.line, e.span.column), offset(e.span.end_line, e.span.end_column),
          e.text) for e in edits), key=lambda item: item[0]))
    if any(one[0] == other[0] for one, other in itertools.pairwise(placed)):
        # two at one place: made one by one from the end, each on the last one's text
        for start, end, new in sorted(placed, key=lambda item: item[0], reverse=True):
            text = text[:start] + new.replace("\n", line_end) + text[end:]
        return text
    pieces: list[str] = []  # a piece an edit, not a copy of the text an edit
    done = 0  # where the text not yet in pieces starts
    for start, end, new in placed:
        pieces += [text[done:start], new.replace("\n", line_end)]
        done = end
    pieces.append(text[done:])
    return "".join(pieces)


def _lines_kept_apart(text: str, placed: list[tuple[int, int, str]]
                      ) -> list[tuple[int, int, str]]:
    """The edits placed (start, end, text; in order), one that empties a line between a
    CR and an LF made to end that line with a CR instead (or with a CRLF, when an LF
    follows, which a CR would join): emptied, its text would leave the two as one CRLF,
    a line less, and every line after it renumbered (an unused label alone on its
    line, removed)."""
    kept = list(placed)
    for index, (start, end, new) in enumerate(placed):
        alone = (index == 0 or placed[index - 1][1] < start) and (
            index + 1 == len(placed) or placed[index + 1][0] > end)
        if new == "" and start < end and alone and text[start - 1:start] == "\r" \
                and text[end:end + 1] == "\n":
            joins_next = text[end + 1:end + 2] == "\n"
            kept[index] = (start, end, "\r") if joins_next else (start, end + 1, "\r")
    return kept
