"""`ir.validate` refuses a malformed IR for each rule it checks, with the message that
names it (the rules several at once: test_lower.py; the shared empty list:
test_shared_empty_list.py; lines and unwritten ends: test_passes.py)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rl1.compiler.backend import ir
from rl1.compiler.backend.ir import (
    Branch,
    Call,
    Compute,
    DecrementBranch,
    End,
    Imm,
    Instruction,
    Jump,
    Load,
    Operate,
    Store,
    StoreBranch,
    Terminator,
    Var,
)
from rl1.vm.language import VARIABLES

A = Var("A")
END = End(1)


def problems(instructions: list[Instruction], terminator: Terminator = END) -> list[str]:
    """What validate says of a program of one block, B0, of these."""
    return ir.validate(ir.Program({"B0": ir.Block("B0", instructions, terminator)}, "B0"))


def test_a_well_formed_block_has_no_problem() -> None:
    assert problems([Load(Imm(-0x8000), 1), Operate("+", Imm(0x7FFF), 1), Store(A, 1),
                     Call("MOV", None, (Imm(12), A), 1, compact=True)],
                    StoreBranch(A, "<", "B0", "B0", 1)) == []


def test_a_block_that_ends_with_no_terminator_is_refused_not_a_crash() -> None:
    # validate asked a Load for the blocks it jumps to (AttributeError) before it said so.
    assert problems([], Load(A, 1)) == [  # type: ignore[arg-type]
        "B0: ends with Load(source=Var(name='A'), line=1), which is not a terminator"]


def test_a_terminator_among_the_instructions_is_refused() -> None:
    assert problems([End(1)]) == [  # type: ignore[list-item]
        "B0: holds End(line=1, written=True), which is not an instruction"]


@pytest.mark.parametrize("value", [-0x8001, 0x8000, 70000])
def test_a_constant_beyond_16_bits_is_refused(value: int) -> None:
    assert problems([Load(Imm(value), 1), Store(A, 1)]) == [
        f"B0: line 1: {value} does not fit 16 bits"]


@pytest.mark.parametrize("instruction", [Operate("+", Imm(1), 1), Store(A, 1)],
                         ids=["operate", "store"])
def test_reading_the_accumulator_before_a_load_is_refused(instruction: Instruction) -> None:
    assert problems([instruction]) == [
        f"B0: line 1: `{instruction}` reads acc before a load sets it"]


def test_an_operation_after_a_load_and_operate_reads_what_it_set() -> None:
    assert problems([Compute(A, "+", Imm(1), 1), Operate("-", A, 1), Store(A, 1)]) == []


def test_a_store_and_branch_before_a_load_is_refused() -> None:
    branch = StoreBranch(A, "=", "B0", "B0", 1)
    assert problems([], branch) == [f"B0: line 1: `{branch}` reads acc before a load sets it"]


@pytest.mark.parametrize("terminator", [
    Branch(Var("AB"), "=", "B0", "B0", 1),
    StoreBranch(Var("#"), "=", "B0", "B0", 1),
    DecrementBranch(Var(""), "B0", "B0", 1),
], ids=["branch", "store-branch", "decrement-branch"])
def test_a_branch_on_what_is_no_variable_is_refused(terminator: Terminator) -> None:
    assert problems([Load(Imm(1), 1)], terminator) == [
        f"B0: branches on `{terminator.var.name}`, which is not a variable"]  # type: ignore[union-attr]


@pytest.mark.parametrize("name", ["AB", "Ab", "", "yz@"])
def test_a_name_of_several_letters_is_no_variable(name: str) -> None:
    # validate looked the name up in the string of the 53 letters: `AB` was a variable.
    assert problems([Load(Var(name), 1), Store(A, 1)]) == [
        f"B0: line 1: `{name}` is not a variable"]


@given(st.text(max_size=3))
def test_a_variable_is_one_of_the_53_letters(name: str) -> None:
    found = problems([Load(Imm(0), 1), Store(Var(name), 1)])
    assert (found == []) == (len(name) == 1 and name in VARIABLES)


@given(st.integers(min_value=-0x20000, max_value=0x20000))
def test_a_constant_is_one_of_16_bits(value: int) -> None:
    found = problems([Load(Imm(value), 1), Store(A, 1)])
    assert (found == []) == (-0x8000 <= value <= 0x7FFF)


@pytest.mark.parametrize("call", [Call("XYZ", None, (), 1), Call("CAM", "Q", (), 1),
                                  Call("MOV", "Z", (Imm(0), Imm(0)), 1)],
                         ids=["no-such-name", "no-such-selector", "a-selector-too-many"])
def test_a_call_of_no_built_in_form_is_refused(call: Call) -> None:
    assert problems([call]) == [
        f"B0: line 1: `{call}` is not a built-in form (END is a terminator)"]


def test_a_compact_call_of_a_constant_beyond_a_byte_is_refused() -> None:
    call = Call("OUT", None, (Imm(1), Imm(200)), 1, compact=True)
    assert problems([call]) == [f"B0: line 1: `{call}`: data does not fit a byte"]
    assert problems([Call("OUT", None, (Imm(1), Imm(200)), 1)]) == []


def test_a_jump_to_a_block_that_exists_is_no_problem() -> None:
    assert problems([], Jump("B0", 1)) == []
    assert problems([], Jump("B9", 1)) == ["B0: jumps to B9, which is not a block"]
