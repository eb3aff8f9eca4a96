"""Sources of a block every few bytes, the costliest IR a source byte (a block's IR is
some 300 bytes), each a first line and a unit repeated after it: the one list of them
for tests/backend/test_compile_memory.py and tests/checker/test_streaming.py, which hold
a compile and a check of each to spec/language.md's bounds under tracemalloc, and
bench/memory.py, which measures `rl1c compile -s` of 8 MiB of each."""

from __future__ import annotations

from typing import NamedTuple


class BlockShape(NamedTuple):
    head: str  # the first line (or lines)
    unit: str  # repeated after it
    name: str  # what the bench prints


BLOCK_SHAPES: dict[str, BlockShape] = {
    # a conditional jump a line, each a block of its own (7 bytes)
    "?A=#01": BlockShape(":01\n", "?A=#01\n", "`?A=#01` lines after `:01`"),
    "?A<#01": BlockShape(":01\n", "?A<#01\n", "`?A<#01` lines after `:01`"),
    "?A>#01": BlockShape(":01\n", "?A>#01\n", "`?A>#01` lines after `:01`"),
    # a jump a line: a block every 4 bytes, which no path reaches
    "#01": BlockShape(":01\n", "#01\n", "`#01` lines after `:01`, a jump each"),
    # a label on each of 96 lines, and jumps between them on all the others
    "labels": BlockShape(
        "".join(f":{n:02d} ?A=#{(n * 37 + 11) % 96:02d}\n" for n in range(96)),
        "".join(f"?A=#{(n * 37 + 5) % 96:02d}\n" for n in range(96)),
        "96 labels, then jumps between them"),
    # a handler's lines, each ending the program (a block each)
    "(END)": BlockShape(":96\n", "(END)\n", "`(END)` lines after `:96`"),
}
