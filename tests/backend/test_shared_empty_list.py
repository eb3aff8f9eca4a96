"""The blocks without instructions share one list (ir.NO_INSTRUCTIONS), which no stage
may change in place: a list a block of `#01` lines was 14 bytes a source byte of the
compile's peak (test_compile_memory.py)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from rl1.compiler.analysis import analyze
from rl1.compiler.backend import ir
from rl1.compiler.backend.driver import OPTIMIZATION_LEVELS, compile_text
from rl1.compiler.backend.lower import lower
from rl1.compiler.strategies import checked_programs


def lowered(text: str) -> ir.Program:
    analysis = analyze(text)
    assert not analysis.has_errors, analysis.diagnostics
    return lower(analysis.program)


def test_blocks_without_instructions_share_one_list_and_the_others_have_their_own() -> None:
    program = lowered(":01 #01\n#01\nA=1;#01\nB=2;?A=#01\n#01\n")
    empty = [block for block in program if not block.instructions]
    assert [block.id for block in empty] == ["L01", "B0", "B3"]
    assert all(block.instructions is ir.NO_INSTRUCTIONS for block in empty)
    assert program.blocks["B1"].instructions == [ir.Load(ir.Imm(1), 3), ir.Store(ir.Var("A"), 3)]
    assert program.blocks["B2"].instructions == [ir.Load(ir.Imm(2), 4), ir.Store(ir.Var("B"), 4)]
    assert ir.NO_INSTRUCTIONS == []


@given(checked_programs(), st.sampled_from(OPTIMIZATION_LEVELS))
def test_no_stage_changes_the_shared_list_in_place(text: str, level: int) -> None:
    compilation = compile_text(text, "generated.rob", level=level, check=True)
    assert compilation.output is not None, compilation.diagnostics
    assert ir.NO_INSTRUCTIONS == []


def test_validate_names_a_change_of_the_shared_list() -> None:
    program = lowered("#01\n:01 (END)\n")
    assert ir.validate(program) == []
    ir.NO_INSTRUCTIONS.append(ir.Load(ir.Imm(7), 1))
    try:
        problems = ir.validate(program)
    finally:
        ir.NO_INSTRUCTIONS.clear()
    assert problems == ["the blocks' shared empty list holds load 7: a pass changed a "
                        "block's list in place, where it must replace it"]


def test_each_block_is_laid_out_with_the_id_of_the_next() -> None:
    program = lowered("A=1\n?A=#01\nB=2\n:01 (END)\n")
    assert [(block.id, following) for block, following in program.laid_out()] == [
        ("B0", "B1"), ("B1", "L01"), ("L01", None)]
    assert list(ir.Program({}, "B0").laid_out()) == []
