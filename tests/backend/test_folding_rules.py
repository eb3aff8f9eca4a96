"""Constant folding (compiler/backend/constants.py) where a known value meets one the
compiler cannot know (a reading), and where it decides a branch: rules that no test
held until mutation testing (tests/mutation/) changed them and every test still
passed."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.semantics import operate
from test_passes import after, run_program

from rl1.compiler.backend import ir
from rl1.compiler.backend.constants import fold_constants
from rl1.vm import isa
from rl1.vm.language import VARIABLES

INT16 = st.integers(-32768, 32767)
# The values that an operator's identity and absorbing rules are about, their
# neighbours, and the shift counts around 16.
EDGES = (-32768, -17, -16, -2, -1, 0, 1, 2, 3, 15, 16, 17, 32767)


def folded_runs(operator: str, known: int, known_first: bool, readings: list[int]
                ) -> list[int]:
    """A of `A=B op C` (`C op B` unless `known_first`), B known, C a reading (KYO's
    centre), folded, then run once on each reading."""
    expression = f"B{operator}C" if known_first else f"C{operator}B"
    program = after(fold_constants, f"B={known}\nC=(KYO)\nA={expression}\n")
    return [run_program(program, {"KYO": [{"centre": reading, "right": 0, "left": 0}]})
            [0][VARIABLES.index("A")] for reading in readings]


@pytest.mark.parametrize(("operator", "known_first"),
                         list(itertools.product(isa.ALU_OPERATORS, (True, False))))
def test_a_known_edge_value_with_a_reading_folds_to_what_the_vm_computes(
        operator: str, known_first: bool) -> None:
    for known in EDGES:
        expected = [operate(operator, known, reading) if known_first
                    else operate(operator, reading, known) for reading in EDGES]
        assert folded_runs(operator, known, known_first, list(EDGES)) == expected, known


@settings(max_examples=100, deadline=None)
@given(operator=st.sampled_from(isa.ALU_OPERATORS), known=INT16, reading=INT16,
       known_first=st.booleans())
def test_any_known_value_with_a_reading_folds_to_what_the_vm_computes(
        operator: str, known: int, reading: int, known_first: bool) -> None:
    expected = operate(operator, known, reading) if known_first \
        else operate(operator, reading, known)
    assert folded_runs(operator, known, known_first, [reading]) == [expected]


@pytest.mark.parametrize("relation", ["=", ">", "<"])
def test_a_branch_on_a_known_value_is_decided_as_it_would_go(relation: str) -> None:
    for known in EDGES:
        program = after(fold_constants, f"A={known}\n?A{relation}#20\nB=1\n:20 (END)\n")
        taken = {"=": known == 0, ">": known > 0, "<": known < 0}[relation]
        variables, _ = run_program(program, {})
        assert variables[VARIABLES.index("B")] == (0 if taken else 1), known


def test_a_computed_value_is_unknown_and_stored_as_it_is() -> None:
    """-O2's Compute (fuse makes it after this pass) leaves the accumulator unknown: a
    store after it stays, and so does what it stores, on IR as fuse leaves it."""
    compute = ir.Compute(ir.Var("B"), "+", ir.Imm(1), 1)
    program = ir.Program({"B0": ir.Block("B0", [ir.Load(ir.Imm(5), 1), ir.Store(ir.Var("B"), 1),
                                                compute, ir.Store(ir.Var("A"), 2)],
                                         ir.End(3))}, "B0")
    assert ir.validate(program) == []
    assert fold_constants(program).blocks["B0"].instructions[-2:] == [
        compute, ir.Store(ir.Var("A"), 2)]


def test_a_call_forgets_the_reserved_variables_it_writes() -> None:
    """x is 1 before (IMG), which writes the image's x there: `x+1` after it is not 2."""
    program = after(fold_constants, "x=1\n(IMG)\nB=x+1\n")
    variables, _ = run_program(program, {"IMG": [{"area": 9, "x": 7, "y": 0, "z": 0}]})
    assert variables[VARIABLES.index("B")] == 8


@pytest.mark.parametrize(("known", "operator"), [(0, "&"), (-1, "|"), (0, "<"), (0, ">")])
def test_a_known_value_no_reading_changes_is_stored_without_the_operation(
        known: int, operator: str) -> None:
    """`0&C`, `-1|C` and 0 shifted are known whatever C is: no operation is left."""
    program = after(fold_constants, f"A=(KYO)\nC=(KYO)\nB={known}\nA=B{operator}C\n")
    assert [str(instruction) for instruction in program.blocks[program.entry].instructions
            ][-2:] == ["load B", "store A"]


@pytest.mark.parametrize("step", ["++", "--"])
def test_a_step_of_a_known_value_folds_to_what_the_vm_computes(step: str) -> None:
    for known in EDGES:
        program = after(fold_constants, f"A={known}\nA{step}\nB=A\n")
        variables, _ = run_program(program, {})
        assert variables[VARIABLES.index("B")] == \
            operate("+" if step == "++" else "-", known, 1), known
