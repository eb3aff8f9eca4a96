"""The whole-program checker with the language server's memo of line segments gives
exactly what it gives from scratch, after any edits: the memo only saves time."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st
from lsprotocol import types

from rl1.compiler.checker import ControlFlowGraph, LineMemo, build_cfg, check_program
from rl1.compiler.frontend.diagnostics import sort_key
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.strategies import lines, programs
from rl1.lsp.document import Document
from rl1.lsp.positions import Columns

# Lines that cut blocks in every way: jumps and (END) mid-line, labels, handlers,
# syntax errors, motion and tracing, reserved variables read and written.
LINE = st.one_of(lines(), st.sampled_from([
    "", ":10 A=1; #10", "?A=#10; B=2", "(END); C=3", ":20 (MOV 3,3); (END)", "(TRC 3)",
    "(TRC 2); (MVI 1,1,40)", ":96 (MOV 0,0); (END)", ":99", "A=(", "#20", "A=x+(IMG)",
    "(KYO); B=u", "v=1; ?v>#96", "(MOV A,0); (TIM 3)", "' just a comment",
]))


@st.composite
def line_edits(draw: st.DrawFn) -> tuple[str, int, str]:
    """(what, where, text): insert a line, delete one, or rewrite one."""
    return (draw(st.sampled_from(["insert", "delete", "rewrite"])),
            draw(st.integers(0, 40)), draw(LINE))


def apply(document: Document, edit: tuple[str, int, str], columns: Columns) -> None:
    what, where, text = edit
    where = min(where, document.line_count - 1)
    if what == "insert":
        start = end = types.Position(where, 0)
        text += "\n"
    elif what == "delete":
        start, end, text = types.Position(where, 0), types.Position(where + 1, 0), ""
    else:
        start = types.Position(where, 0)
        end = types.Position(where, len(document.line_text(where + 1)))
    document.apply(types.TextDocumentContentChangePartial(range=types.Range(start, end),
                                                          text=text), columns)
    document.version += 1


def shape(graph: ControlFlowGraph) -> list[tuple[object, ...]]:
    """Everything the rules see of a graph, effects compared by value."""
    return [(block.statements, block.labels, block.successors, block.handlers, block.opaque,
             block.effects.operations, block.effects.first_event, block.effects.reads,
             block.effects.writes, block.effects.observes,
             graph.device_on_entry[block.index]) for block in graph.blocks]


@settings(max_examples=150, deadline=None)
@given(text=st.one_of(programs(max_lines=15), st.lists(LINE, max_size=15).map("\n".join)),
       edits=st.lists(line_edits(), min_size=1, max_size=8))
def test_the_memo_never_changes_a_result_after_edits(
        text: str, edits: list[tuple[str, int, str]]) -> None:
    columns = Columns()
    document = Document("file:///t.rob", text, 1)
    check_program(document.program(), document.memo)  # warm the memo: edits must keep it right
    for edit in edits:
        apply(document, edit, columns)
        program = document.program()
        assert document.program() == parse_program(document.text())[0]
        warm = check_program(program, document.memo)
        assert sorted(warm, key=sort_key) == sorted(check_program(program), key=sort_key)
        assert shape(build_cfg(program, document.memo)) == shape(build_cfg(program))
        # The walk that reused the last one keeps the same books as a walk afresh (and
        # so does not grow with the number of edits).
        fresh = LineMemo()
        build_cfg(program, fresh)
        assert document.memo.last_walk is not None and fresh.last_walk is not None
        assert document.memo.last_walk.restarts == fresh.last_walk.restarts


@settings(max_examples=150, deadline=None)
@given(texts=st.lists(st.lists(LINE, max_size=12).map("\n".join), min_size=1, max_size=5))
def test_one_memo_across_unrelated_programs_agrees_with_none(texts: list[str]) -> None:
    memo = LineMemo()
    for text in texts:
        program = parse_program(text)[0]
        assert shape(build_cfg(program, memo)) == shape(build_cfg(program))
        assert check_program(program, memo) == check_program(program)


def test_the_memo_forgets_replaced_lines_and_still_agrees() -> None:
    memo = LineMemo()
    long = parse_program(":10 (TRC 3); (MOV 3,3)\n" + "A=x+1; (KYO)\n" * 1500 + "#10\n")[0]
    check_program(long, memo)
    short = parse_program(":10 (TRC 2); (MOV A,0); #10\n(END)\n")[0]
    for program in (short, long, short):  # the long program's lines are dropped, then back
        assert check_program(program, memo) == check_program(program)
        assert shape(build_cfg(program, memo)) == shape(build_cfg(program))


@settings(max_examples=100, deadline=None)
@given(text=st.lists(LINE, max_size=15).map("\n".join),
       edits=st.lists(line_edits(), min_size=1, max_size=8))
def test_blocks_taken_over_from_the_last_graph_agree_with_new_ones(
        text: str, edits: list[tuple[str, int, str]]) -> None:
    """The memo's graph reuses the Blocks of cuts an edit did not touch: their jumps,
    and the graph's lists of labelled and opaque blocks, are those of a fresh graph."""
    columns = Columns()
    document = Document("file:///t.rob", text, 1)
    build_cfg(document.program(), document.memo)
    for edit in edits:
        apply(document, edit, columns)
        warm, fresh = build_cfg(document.program(), document.memo), build_cfg(document.program())
        assert [block.jump for block in warm.blocks] == [block.jump for block in fresh.blocks]
        assert [block.index for block in warm.blocks] == list(range(len(fresh.blocks)))
        assert (warm.labelled, warm.opaque) == (fresh.labelled, fresh.opaque)
