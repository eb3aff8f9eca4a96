"""The check without the tree (checker/streaming.py, `rl1c check`'s path) gives exactly
the diagnostics of the check on the tree (`analyze`), in the same order (on generated
programs: test_checker_properties.py), and holds the bound of spec/language.md on
memory per source byte."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.block_shapes import BLOCK_SHAPES

from rl1.compiler.analysis import analyze, diagnose
from rl1.compiler.checker.streaming import BlockPlaces, SourceStatements
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.parser import parse_line
from rl1.compiler.frontend.source import LineIndex


def assert_same(text: str) -> None:
    expected = analyze(text).diagnostics
    assert diagnose(text) == expected
    assert [repr(d) for d in diagnose(text)] == [repr(d) for d in expected]


@pytest.mark.parametrize("text", [
    "",  # no lines
    "\n\n' only a comment\n",
    ":10 A=s; (TRC 3); (MOV 3,3)\n?A=#10; B=t\n:20\n",  # handler edges, unset reads
    ":10 A=1\n#10\nB=2\n",  # a busy loop, code after a jump
    "A=1 B=2\n:10 (TRC 2); (MOV 1,1)\n' rl1: allow W0301\n",  # broken, directives
    "(MOV 3,3)\r\nA=u\rB=v ' rl1: allow W0401\n(END)",  # every line end, no final one
    "A=(ENDD)\n(ENDD)\n",  # an unknown call as an operand and as a statement
    "(TRC 3); (MVI 1,1,50)\n" * 3 + "(END)\n",
    # consecutive broken lines, which the streaming check makes one block: labelled
    # or not, after a jump or `(END)`, around blank lines, jumped to by a missing label
    "A=1 B=2\n\nC=3 D=4\n:10 E=5 F=6\nG=7 H=8\n#20\nI=9 J=1\nK=2 L=3\n",
    "(END)\nA=1 B=2\nC=3 D=4\n:10\nE=5 F=6\n' note\nG=7 H=8\n:20 A=1; #10\n",
    ":A\n:B\nA=1 B=2\n#30\n(MOV 1,1) X\n:96 (TRC 2) Y\nA=1 B=2\n",
    # reads that may be unset, held by line and column: several on a line, with the
    # line's own diagnostics, allowed by a comment, after a call that sets one
    "A=s+t; B=s; C=99999\nA=1 B=2\n(IMG 1); C=s+u ' rl1: allow W0401\nD=v; #10\n"
    "t=w\n?x=1#20\n:10 E=(ULT 1)+u+s\n",
    # blocks that never run and are alike, which one object stands for: each says where
    # it is (an E0203 a line, the spans of W0601 and W0602), a label ends the run, and
    # the last is where the program runs off its end
    "#10\n#05\n#05; A=1\n#05\n(END)\n(END)\n:10 #1\n#1\n(TIM 1); #1\n#1\n",
    ":20 (MOV 1,1); #30\n(END)\n(END)\n:30 ?A=1#20\n#20\n#20\n",
])
def test_programs_with_each_rule_give_the_same_diagnostics(text: str) -> None:
    assert_same(text)


def test_a_blocks_statements_are_read_from_its_lines_again() -> None:
    text = "A=1; B=2\n\n' comment\nC=3; #10\n"
    lines = LineIndex(text)
    last = parse_line(lines[3], 4)[0].statements[1]
    assert isinstance(last, ast.Goto)
    places = BlockPlaces(lines)
    places.add(2, 0, 1, 3, 3, 1, 6)  # block 2, from B=2 to #10; blocks 0 and 1 hold none
    assert list(places.length) == [0, 0, 3] and list(places.target) == [0, 0, 6]
    assert last.target.span.column == 6
    statements = SourceStatements(places, 2, last)
    assert len(statements) == 3
    assert statements.jump is last and not statements.ends
    assert [(s.span.line, s.span.column) for s in statements] == [(1, 6), (4, 1), (4, 6)]
    assert statements[-1] == last and statements[2] == last
    assert isinstance(statements[0], ast.Assign) and statements[0].target.name == "B"
    assert isinstance(statements[1], ast.Assign) and statements[1].target.name == "C"
    assert [s.span.line for s in statements[:1]] == [1]
    assert statements[-1:] == (last,)
    with pytest.raises(IndexError):
        statements[3]


def test_a_blocks_last_statement_is_read_from_its_line_again() -> None:
    """The jump a block keeps may stand for another block's (graph.Block.jump): its last
    statement, read again, is its own, where it is; an `(END)` is kept as a flag."""
    text = "A=1\nB=2; (END); C=3\n#10\n#10\n"
    lines = LineIndex(text)
    end = parse_line(lines[1], 2)[0].statements[1]
    places = BlockPlaces(lines)
    places.add(0, 0, 0, 3, 1, 1, 0)  # from A=1 to (END)
    places.add(1, 2, 0, 1, 2, 0, 1)  # #10 on line 3
    places.add(2, 3, 0, 1, 3, 0, 1)  # #10 on line 4
    statements = SourceStatements(places, 0, True)
    assert statements.ends and statements.jump is None
    last = statements[-1]
    assert last is not end and last == end
    assert (last.span.line, last.span.column) == (2, 6)
    assert [ast.is_end(s) for s in statements] == [False, False, True]
    shared = parse_line(lines[2], 3)[0].statements[0]
    assert isinstance(shared, ast.Goto)
    second = SourceStatements(places, 2, shared)
    assert second.jump is shared and not second.ends
    assert second[-1].span.line == 4


def test_blocks_that_jump_alike_share_their_jump_and_each_reads_its_own() -> None:
    """Undefined targets (E0203) and busy loops (W0604) are reported at the jump of each
    block, not at the jump the blocks share."""
    for text in ("#10\n#10\nA=1; #10\n?B=#10\n?B=#10\n",
                 ":10 A=1\n#10\n#10\n:20 ?A=#20\n?A=#20\n#20\n"):
        assert_same(text)
        found = [(d.code, d.span.line) for d in diagnose(text)
                 if d.code in ("E0203", "W0604")]
        assert found == [(d.code, d.span.line) for d in analyze(text).diagnostics
                         if d.code in ("E0203", "W0604")]
        assert found


# Lines of jumps that blocks share (graph.Block.jump), labels that define or miss their
# targets, loops, unreachable code, and lines with fixes.
JUMPY_LINES = ("#10", "#10", "?A=#10", "?A=#10", "?B>#20", "#1", "#123", ":10", ":20 (TIM 1)",
               ":10 A=A+1", "A=1; #20", "(END)", "A=1 B=2", ":30 ?A<#30", "(MOV 3,3)",
               "GOTO 10", "(mov 3,3)", "A=s", ":5 (TIM 10)", ":7", "#5", "(TRC 3)")


@settings(max_examples=200, deadline=None)
@given(st.lists(st.sampled_from(JUMPY_LINES), max_size=16), st.sampled_from(["\n", "\r\n"]))
def test_blocks_that_share_jumps_give_the_diagnostics_of_the_tree(lines: list[str],
                                                                  ending: str) -> None:
    assert_same(ending.join(lines))


# Sources with a diagnostic a line, at a size tracemalloc measures in seconds: a first
# line, then one line repeated; measured with each output format, which writes each
# diagnostic its own way.
SOURCES = {
    "lines of 19,999 characters": ("", ";".join(["A=1"] * 4999) + "\n"),
    "`A=1` lines": ("", "A=1\n"),
    "lines with a syntax error": ("", "A=1 B=2\n"),
    # a block of a million runs that write a reserved variable: 128 B/B when it held
    # each run's effects until it ended (effects.Combining)
    "`t=1` lines": ("", "t=1\n"),
    # a W0401 a line: 66 B/B when each was held whole (250 bytes)
    "`A=s` lines": ("", "A=s\n"),
    # and an E0203 a line: 172 B/B when each was held whole (400 bytes)
    "`#01` lines without `:01`": ("", "#01\n"),
    # a block every 3 bytes that never runs (each follows a jump, and has an E0202): 74
    # B/B when each was a SourceBlock of its own (140 bytes)
    "`#1` lines": ("", "#1\n"),
}
# And the project's shapes of a block every few bytes (support.block_shapes, which
# bench/memory.py measures), whose diagnostics are one or two whatever their size, so
# that one output format measures them: a block a line, 178 B/B when each block's record
# was a Cut, a Block, the tree of its last statement and effects of its own, and each
# block had a dict of triggers (`(END)` lines); a block a line that jumps, 163 and 141
# B/B when each block held its jump's tree, its statements' places as an object, a tuple
# of its successors, and the loop rule a set and lists of ints as large as the program
# (`#01` and `?A=#01` lines).
SHAPES = {f"block shape {name}": (shape.head, shape.unit)
          for name, shape in BLOCK_SHAPES.items()}
FORMATS = {**dict.fromkeys(SOURCES, ("human", "sarif")), **dict.fromkeys(SHAPES, ("human",))}
SOURCE_CHARACTERS = 256 * 1024

# The text is checked once; then each format is written by a process forked for it, as
# if that process had checked the text itself, so that no format's writing counts in
# another's peak.
MEASURE = textwrap.dedent("""
    import io, os, sys, tracemalloc
    from rl1.compiler.analysis import diagnose_compactly
    from rl1.compiler.reporting.render import FileDiagnostics, exit_status, summary, write_report
    from rl1.compiler.reporting.selection import Selection
    head, line, *output_formats = sys.argv[1:]
    text = head + line * ({characters} // len(line))

    class Nowhere(io.TextIOBase):
        def write(self, text):
            return len(text)

    tracemalloc.start()
    held = Selection().apply_compact(diagnose_compactly(text))
    for output_format in output_formats:
        if os.fork() == 0:
            files = [FileDiagnostics("big.rob", text, held)]
            write_report(Nowhere(), files, output_format)
            summary(files), exit_status(files)
            print(output_format, tracemalloc.get_traced_memory()[1] / len(text), flush=True)
            os._exit(0)
    sys.exit(any(os.wait()[1] for _ in output_formats))
""")


@pytest.mark.parametrize("kind", FORMATS)
def test_checking_takes_at_most_64_bytes_a_source_byte(kind: str) -> None:
    """The peak of the allocations of what `rl1c check` does beyond reading its text (in
    a process of its own, so that no other test's caches count), against
    spec/language.md's bound, with each output format. A syntax error a line took 67
    B/B in its diagnostics alone (an E0101 with its fix, 516 bytes of objects a line)
    before they were held compactly (checker/compact.py)."""
    script = MEASURE.format(characters=SOURCE_CHARACTERS)
    measured = subprocess.run([sys.executable, "-c", script, *{**SOURCES, **SHAPES}[kind],
                               *FORMATS[kind]], capture_output=True, text=True, check=False)
    assert measured.returncode == 0, measured.stderr
    per_byte = {output_format: float(peak) for output_format, peak
                in (line.split() for line in measured.stdout.splitlines())}
    assert sorted(per_byte) == sorted(FORMATS[kind])
    assert all(peak <= 64 for peak in per_byte.values()), per_byte


BEYOND_DIAGNOSTICS = textwrap.dedent("""
    import sys, tracemalloc
    from rl1.compiler.analysis import diagnose
    text = "A=1 B=2\\n" * ({characters} // 8)
    tracemalloc.start()
    found = diagnose(text)
    kept, peak = tracemalloc.get_traced_memory()
    print(len(found), (peak - kept) / len(text))
""")


def test_broken_lines_cost_little_beyond_their_diagnostics() -> None:
    """A source of a syntax error a line (bench/memory.py's third) holds its diagnostics
    (`diagnose`'s list, which `--fix` reads) and little else at its peak: consecutive
    broken lines are one block of the graph (they were a block each: 62 B/B beyond the
    diagnostics), and sorting takes no key tuple a diagnostic (9 B/B)."""
    script = BEYOND_DIAGNOSTICS.format(characters=SOURCE_CHARACTERS)
    measured = subprocess.run([sys.executable, "-c", script], capture_output=True,
                              text=True, check=True)
    count, beyond = measured.stdout.split()
    assert int(count) == SOURCE_CHARACTERS // 8  # an E0101 a line
    assert float(beyond) <= 8


def test_the_warnings_of_reads_of_one_unset_variable_share_their_texts() -> None:
    """A source that reads `s` unset on each of its lines holds one message and one help
    of W0401 for them all (it held 57 B/B of copies: 124 B/B at its peak, 66 now)."""
    found = [d for d in diagnose("A=s\nB=s+s\n" * 3) if d.code == "W0401"]
    assert len(found) == 9
    assert len({id(d.message) for d in found}) == len({id(d.help) for d in found}) == 1


def test_the_warnings_of_writes_of_one_reserved_variable_share_their_message() -> None:
    """A source that writes `t` on each of its lines makes the message of W0402 once (a
    tenth of `rl1c check`'s time went to making it again for each line)."""
    found = [d for d in diagnose("t=1\nA=2; t=3\n" * 3) if d.code == "W0402"]
    assert len(found) == 6
    assert len({id(d.message) for d in found}) == 1
