"""Lowering to IR: the instruction sequence of each construct, blocks and edges, the
IR's invariants and its printed form."""


import pytest
from support import SAMPLE

from rl1.compiler.backend import flow, ir, ir_text
from rl1.compiler.backend.ir import (
    Branch,
    Call,
    End,
    Imm,
    Jump,
    Load,
    Operate,
    R,
    StepVar,
    Store,
    Var,
)
from rl1.compiler.backend.lower import LoweringError, lower
from rl1.compiler.frontend.parser import parse_program


def lower_text(text: str) -> ir.Program:
    program, diagnostics = parse_program(text)
    assert diagnostics == []
    return lower(program)


def predecessors(program: ir.Program) -> dict[ir.BlockId, list[ir.BlockId]]:
    """Each block's predecessors' ids, in layout order (flow.Places)."""
    places = flow.Places(program)
    return {block.id: [places.blocks[pred].id for pred in places.predecessors(place)]
            for place, block in enumerate(places.blocks)}


def only_block(text: str) -> ir.Block:
    (block,) = lower_text(text)
    return block


def test_expression_is_left_to_right_without_precedence() -> None:
    # C=a<3+b>6+C is (((a<<3)+b)>>6)+C.
    block = only_block("C=a<3+b>6+C")
    assert block.instructions == [
        Load(Var("a"), 1), Operate("<", Imm(3), 1), Operate("+", Var("b"), 1),
        Operate(">", Imm(6), 1), Operate("+", Var("C"), 1), Store(Var("C"), 1),
    ]
    assert block.terminator == End(1)


def test_call_operand_runs_after_the_operands_before_it() -> None:
    # x is loaded before IMG overwrites it, and IMG's result is read from R.
    block = only_block("A=x+(IMG)")
    assert block.instructions == [
        Load(Var("x"), 1), Call("IMG", None, (), 1), Operate("+", R, 1), Store(Var("A"), 1),
    ]


def test_call_as_first_operand_is_loaded_from_r() -> None:
    block = only_block("A=(ULT B)-180")
    assert block.instructions == [
        Call("ULT", "B", (), 1), Load(R, 1), Operate("-", Imm(180), 1), Store(Var("A"), 1),
    ]


def test_constants_are_16_bit_immediates() -> None:
    block = only_block("A=$FFFF; B=-32768; C=$8000^32767")
    assert block.instructions == [
        Load(Imm(-1), 1), Store(Var("A"), 1),
        Load(Imm(-32768), 1), Store(Var("B"), 1),
        Load(Imm(-32768), 1), Operate("^", Imm(32767), 1), Store(Var("C"), 1),
    ]


def test_increment_and_decrement() -> None:
    block = only_block("@++\nz--")
    assert block.instructions == [StepVar(Var("@"), "++", 1), StepVar(Var("z"), "--", 2)]
    assert block.terminator == End(2)


def test_call_arguments_constants_as_immediates_variables_by_name() -> None:
    block = only_block("(MVI 3,c,-50); (CAM P d); (KYO); (fzo $10, A)")
    assert block.instructions == [
        Call("MVI", None, (Imm(3), Var("c"), Imm(-50)), 1),
        Call("CAM", "P", (Var("d"),), 1),
        Call("KYO", None, (), 1),
        Call("FZO", None, (Imm(16), Var("A")), 1),
    ]


def test_label_starts_a_block_entered_by_an_explicit_jump() -> None:
    program = lower_text("A=1\n:10 B=2\n")
    assert list(program.blocks) == ["B0", "L10"]
    first, labelled = program
    assert first.terminator == Jump("L10", 2)
    assert labelled.instructions == [Load(Imm(2), 2), Store(Var("B"), 2)]
    assert labelled.terminator == End(2)


def test_program_starting_with_a_label_enters_at_that_label() -> None:
    program = lower_text(":05 A++; #05")
    assert program.entry == "L05"
    assert program.blocks["L05"].terminator == Jump("L05", 1)
    assert predecessors(program) == {"L05": ["L05"]}


def test_goto_ends_the_block_and_code_after_it_has_no_predecessor() -> None:
    program = lower_text("#10; A=1\n:10 (END)\n")
    assert [block.terminator for block in program] == [
        Jump("L10", 1), Jump("L10", 2), End(2),
    ]
    assert predecessors(program) == {"B0": [], "B1": [], "L10": ["B0", "B1"]}


def test_conditional_jump_branches_to_the_label_or_the_next_statement() -> None:
    program = lower_text(":10 ?d=#10; ?A>#20; ?@<#10\n:20\n")
    assert [block.terminator for block in program] == [
        Branch(Var("d"), "=", "L10", "B0", 1),
        Branch(Var("A"), ">", "L20", "B1", 1),
        Branch(Var("@"), "<", "L10", "B2", 1),
        Jump("L20", 2),
        End(2),
    ]
    assert program.successors("L10") == ("L10", "B0")
    assert predecessors(program)["L20"] == ["B0", "B2"]


def test_end_ends_the_block_and_falling_off_the_end_ends_the_program() -> None:
    program = lower_text("(END)\nA=1\n\n' comment\n")
    first, after = program
    assert first.terminator == End(1)
    assert after.terminator == End(4)  # the program's last line


def test_empty_program_is_one_block_that_ends() -> None:
    (block,) = lower_text("")
    assert block.instructions == [] and block.terminator == End(1)


def test_handler_labels_map_to_their_blocks() -> None:
    program = lower_text(":96 (MOV 0,0)\n:97\n:50\n:99 (END)\n")
    assert program.handlers == {96: "L96", 97: "L97", 99: "L99"}


def test_sample_lowers_to_valid_ir() -> None:
    program = lower_text(SAMPLE.read_text(encoding="utf-8"))
    assert ir.validate(program) == []
    assert program.handlers == {96: "L96", 99: "L99"}
    labels = [block_id for block_id in program.blocks if block_id.startswith("L")]
    assert labels == ["L10", "L12", "L13", "L14", "L20", "L21", "L22", "L29", "L40",
                      "L96", "L99"]
    # `:13` is reached from the `#13` after `d=-450` and by falling out of `:12`.
    assert predecessors(program)["L13"] == ["B2", "L12"]


@pytest.mark.parametrize("text", ["#10", ":10\n:10", "A=(MOV 1,1)", "(TRC 9)", "A=40000"])
def test_programs_the_checker_refuses_do_not_lower(text: str) -> None:
    program, _ = parse_program(text)
    with pytest.raises(LoweringError):
        lower(program)


# The IR's own invariants ---------------------------------------------------------------


def test_validator_reports_each_broken_invariant() -> None:
    program = ir.Program(
        {
            "B0": ir.Block("B0", [Load(R, 1), Store(Var("Q1"), 1)], Jump("L42", 1)),
            "L96": ir.Block("L96", [Call("MOV", None, (Imm(1),), 2),
                                    Call("TRC", None, (Imm(4),), 2)], End(2)),
            "X": ir.Block("Y", [Call("END", None, (), 3)], End(3)),
        },
        entry="L96",
        handlers={95: "B0", 96: "L50"},
    )
    assert ir.validate(program) == [
        "the entry block L96 is not the first block",
        "B0: line 1: `load R` reads R before a call sets it",
        "B0: line 1: `Q1` is not a variable",
        "B0: jumps to L42, which is not a block",
        "L96: line 2: `call MOV 1` takes 2 arguments",
        "L96: line 2: `call TRC 4`: mode must lie in 0..3",
        "block Y is filed under the id X",
        "X: line 3: `call END` is not a built-in form (END is a terminator)",
        "handler :95 is not one of :96-:99",
        "handler :96 names L50, which is not a block",
    ]


def test_r_is_not_set_by_a_call_without_a_result() -> None:
    block = ir.Block("B0", [Call("IMG", None, (), 1), Call("FZI", None, (), 1),
                            Load(R, 1), Store(Var("A"), 1)], End(1))
    assert ir.validate(ir.Program({"B0": block}, "B0")) == [
        "B0: line 1: `load R` reads R before a call sets it",
    ]


def test_printer_shows_header_blocks_predecessors_and_lines() -> None:
    text = ir_text.format_program(lower_text("A=(IMG)-1\n:96 ?A>#96\n(MOV 1,-2); B--"))
    assert text == (
        "entry B0\n"
        "handler :96 L96\n"
        "\n"
        "B0:\n"
        "     1  call IMG\n"
        "     1  load R\n"
        "     1  sub 1\n"
        "     1  store A\n"
        "     2  jump L96\n"
        "\n"
        "L96:  ; from B0, L96\n"
        "     2  if A>0 then L96 else B1\n"
        "\n"
        "B1:  ; from L96\n"
        "     3  call MOV 1, -2\n"
        "     3  dec B\n"
        "     3  end\n"
    )
