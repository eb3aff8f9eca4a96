"""`rl1c compile`'s memory per source byte on the costliest source it compiles: lines of
`A=1` statements, which the dead-store pass of the default level takes down to one store,
so the IR of every statement is held before it goes."""

from __future__ import annotations

import subprocess
import sys
import textwrap

# bench/memory.py's source with lines of 1,999 characters instead of 19,999, at a size
# tracemalloc measures in seconds (the tokens of one long line, 10 MB while it is parsed,
# would be 38 B/B of 256 KiB but are 1.2 of bench/memory.py's 8 MiB).
SOURCE_CHARACTERS = 256 * 1024

MEASURE = textwrap.dedent("""
    import tracemalloc
    from rl1.compiler.backend.driver import compile_text
    line = ";".join(["A=1"] * 499) + "\\n"
    text = line * ({characters} // len(line))
    tracemalloc.start()
    compilation = compile_text(text, "big.rob")
    assert compilation.output is not None, compilation.diagnostics
    print(tracemalloc.get_traced_memory()[1] / len(text))
""")


def test_compiling_takes_at_most_64_bytes_a_source_byte() -> None:
    """The peak of the allocations of a compile beyond its text (in a process of its own,
    so that no other test's caches count), against spec/language.md's bound: 155 B/B
    when the whole syntax tree (95 of them) was held beside the IR while it was made and
    optimized; 62 once the text was checked as `rl1c check` checks it, holding no tree,
    and each line parsed again as it is lowered (the IR, 49, the rest); 42 with one
    object for each variable and constant in the IR."""
    script = MEASURE.format(characters=SOURCE_CHARACTERS)
    measured = subprocess.run([sys.executable, "-c", script], capture_output=True,
                              text=True, check=True)
    assert float(measured.stdout) <= 64


BRANCHES = textwrap.dedent("""
    import tracemalloc
    from rl1.compiler.backend.driver import compile_text
    text = ":01\\n" + "?A=#01\\n" * ({characters} // 7)
    tracemalloc.start()
    compilation = compile_text(text, "branches.rob", strip_debug=True)
    assert compilation.output is not None, compilation.diagnostics
    print(tracemalloc.get_traced_memory()[1] / len(text))
""")


def test_a_block_a_line_takes_at_most_128_bytes_a_source_byte() -> None:
    """The costliest IR a byte: a conditional jump a line, each a block of its own (7
    bytes). The dead-store pass held a set of the live variables a block (2 KB, all 53
    live): 445 B/B at its peak; 103 once equal sets are one object and a block's id and
    each label's are one string (the IR 58 -> 42 B/B), the peak now where the check's
    graph is held beside the IR. Above spec/language.md's 64, which sources of long
    lines keep."""
    script = BRANCHES.format(characters=SOURCE_CHARACTERS)
    measured = subprocess.run([sys.executable, "-c", script], capture_output=True,
                              text=True, check=True)
    assert float(measured.stdout) <= 128
