"""The check without the tree (checker/streaming.py, `rl1c check`'s path) gives exactly
the diagnostics of the check on the tree (`analyze`), in the same order (on generated
programs: test_checker_properties.py), and holds the bound of spec/language.md on
memory per source byte."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from rl1.compiler.analysis import analyze, diagnose
from rl1.compiler.checker.streaming import SourceStatements
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
])
def test_programs_with_each_rule_give_the_same_diagnostics(text: str) -> None:
    assert_same(text)


def test_a_blocks_statements_are_read_from_its_lines_again() -> None:
    text = "A=1; B=2\n\n' comment\nC=3; #10\n"
    lines = LineIndex(text)
    last = parse_line(lines[3], 4)[0].statements[1]
    statements = SourceStatements(lines, 0, 1, 3, 3, 1, last)  # from B=2 to #10
    assert len(statements) == 3
    assert statements.jump is last and not statements.ends
    assert [(s.span.line, s.span.column) for s in statements] == [(1, 6), (4, 1), (4, 6)]
    assert statements[-1] is last and statements[2] is last
    assert isinstance(statements[0], ast.Assign) and statements[0].target.name == "B"
    assert isinstance(statements[1], ast.Assign) and statements[1].target.name == "C"
    assert [s.span.line for s in statements[:1]] == [1]
    assert statements[-1:] == (last,)
    with pytest.raises(IndexError):
        statements[3]


def test_a_blocks_last_statement_is_kept_only_when_it_jumps() -> None:
    """An `(END)` that ends a block is read from its line again, as the others are."""
    text = "A=1\nB=2; (END); C=3\n"
    lines = LineIndex(text)
    end = parse_line(lines[1], 2)[0].statements[1]
    statements = SourceStatements(lines, 0, 0, 3, 1, 1, end)  # from A=1 to (END)
    assert statements.ends and statements.jump is None
    last = statements[-1]
    assert last is not end and last == end
    assert (last.span.line, last.span.column) == (2, 6)
    assert [ast.is_end(s) for s in statements] == [False, False, True]


# bench/memory.py's sources, at a size tracemalloc measures in seconds.
SOURCES = {
    "lines of 19,999 characters": ";".join(["A=1"] * 4999) + "\n",
    "`A=1` lines": "A=1\n",
    "lines with a syntax error": "A=1 B=2\n",
    # a block of a million runs that write a reserved variable: 128 B/B when it held
    # each run's effects until it ended (effects.Combining)
    "`t=1` lines": "t=1\n",
    # a block a line: 178 B/B when each block's record was a Cut, a Block, the tree of its
    # last statement and effects of its own, and each block had a dict of triggers
    "`(END)` lines": "(END)\n",
    # a W0401 a line: 66 B/B when each was held whole (250 bytes)
    "`A=s` lines": "A=s\n",
}
SOURCE_CHARACTERS = 256 * 1024

MEASURE = textwrap.dedent("""
    import io, sys, tracemalloc
    from rl1.compiler.analysis import diagnose_compactly
    from rl1.compiler.reporting.render import FileDiagnostics, exit_status, summary, write_report
    from rl1.compiler.reporting.selection import Selection
    line, output_format = sys.argv[1:]
    text = line * ({characters} // len(line))

    class Nowhere(io.TextIOBase):
        def write(self, text):
            return len(text)

    tracemalloc.start()
    held = Selection().apply_compact(diagnose_compactly(text))
    files = [FileDiagnostics("big.rob", text, held)]
    write_report(Nowhere(), files, output_format)
    summary(files), exit_status(files)
    print(tracemalloc.get_traced_memory()[1] / len(text))
""")


@pytest.mark.parametrize("output_format", ["human", "sarif"])
@pytest.mark.parametrize("kind", SOURCES)
def test_checking_takes_at_most_64_bytes_a_source_byte(kind: str, output_format: str) -> None:
    """The peak of the allocations of what `rl1c check` does beyond reading its text (in
    a process of its own, so that no other test's caches count), against
    spec/language.md's bound. A syntax error a line took 67 B/B in its diagnostics alone
    (an E0101 with its fix, 516 bytes of objects a line) before they were held compactly
    (checker/compact.py)."""
    script = MEASURE.format(characters=SOURCE_CHARACTERS)
    measured = subprocess.run([sys.executable, "-c", script, SOURCES[kind], output_format],
                              capture_output=True, text=True, check=True)
    assert float(measured.stdout) <= 64


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
