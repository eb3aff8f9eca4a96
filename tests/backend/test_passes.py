"""Each optimizer pass alone, on small IR: what it rewrites, and what it must leave."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.semantics import operate

from rl1.compiler.backend import ir, ir_text, optimize
from rl1.compiler.backend.codegen import generate
from rl1.compiler.backend.constants import fold_constants
from rl1.compiler.backend.control import simplify_control
from rl1.compiler.backend.copies import propagate_copies
from rl1.compiler.backend.dead_stores import remove_dead_stores
from rl1.compiler.backend.final_end import leave_out_final_end
from rl1.compiler.backend.ir import (
    Block,
    Branch,
    Call,
    End,
    Imm,
    Jump,
    Load,
    Operate,
    Program,
    StepVar,
    Store,
    Var,
)
from rl1.compiler.backend.lower import lower
from rl1.compiler.backend.peephole import rewrite_steps
from rl1.compiler.backend.superinstructions import fuse
from rl1.compiler.backend.tails import merge_tails
from rl1.compiler.differential import AstEngine, VmEngine, judge
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.strategies import Run
from rl1.vm import ilc
from rl1.vm.hardware import Blocking
from rl1.vm.machine import Machine
from rl1.vm.scripted import ScriptedDevice, parse_script
from rl1.vm.verifier import verify

A, B, C, X = Var("A"), Var("B"), Var("C"), Var("x")
ENGINES = (AstEngine(), VmEngine(0), VmEngine(1), VmEngine(2))


def lowered(text: str) -> Program:
    program, diagnostics = parse_program(text)
    assert diagnostics == []
    return lower(program)


def after(run: optimize.Pass, text: str) -> Program:
    program = run(lowered(text))
    assert ir.validate(program) == []
    return program


def code(program: Program, block_id: str | None = None) -> list[str]:
    """A block's instructions and terminator as IR text, without their lines."""
    block = program.blocks[block_id or program.entry]
    return [str(item) for item in [*block.instructions, block.terminator]]


# Constant folding and propagation ------------------------------------------------------


def test_expressions_of_known_values_fold_to_one_load() -> None:
    program = after(fold_constants, "A=5; B=A+3<2; C=B-A")
    assert code(program) == ["load 5", "store A", "load 32", "store B", "load 27",
                             "store C", "end"]


def test_every_variable_starts_at_zero_so_storing_zero_first_does_nothing() -> None:
    assert code(after(fold_constants, "A=0; B=A+C; (MOV B,B)")) == ["call MOV 0, 0", "end"]


@settings(max_examples=300, deadline=None)
@given(st.sampled_from("+-&|^<>"), st.integers(-32768, 32767), st.integers(-32768, 32767))
def test_folding_follows_the_16_bit_wrap_and_shift_rules(op: str, left: int, right: int
                                                         ) -> None:
    program = after(fold_constants, f"A={left}\nB={right}\nC=A{op}B; (FZO C,C)")
    result = Imm(operate(op, left, right))
    assert program.blocks[program.entry].instructions[-1] == Call("FZO", None,
                                                                  (result, result), 3)


def test_an_unknown_operand_gets_the_known_value_so_far_loaded_before_it() -> None:
    assert code(after(fold_constants, "A=2+3+(KYO)-1")) == [
        "call KYO", "load 5", "add R", "sub 1", "store A", "end"]
    # 0+B is B, 0&B is 0, and operations that change nothing go.
    assert code(after(fold_constants, "B=(KYO); A=0+B+0|0; C=0&B<3")) == [
        "call KYO", "load R", "store B", "load B", "store A", "end"]


def test_knowledge_crosses_blocks_and_a_known_branch_becomes_a_jump() -> None:
    program = after(fold_constants, "A=3\n:10 B=A+1\n?A=#20\nC=B\n:20 (END)")
    # A is 3 wherever :10 runs, so `?A=#20` never jumps: B1 (line 4) follows.
    assert code(program, "L10") == ["load 4", "store B", "jump B1"]
    # C=B loads B, which holds 4: the variable stays (LDV is a byte shorter than LDI).
    assert code(program, "B1") == ["load B", "store C", "jump L20"]


def test_a_loop_forgets_what_its_body_changes() -> None:
    program = after(fold_constants, "A=3; B=7\n:10 A--; C=B+1; ?A>#10")
    assert code(program, "L10") == ["dec A", "load 8", "store C",
                                    "if A>0 then L10 else B1"]


def test_handlers_and_reserved_variables_start_unknown() -> None:
    program = after(fold_constants, "A=5; x=1; (TRC 3); (MOV 1,1); (IMG); B=x\n:96 C=A")
    assert code(program)[-3:] == ["load x", "store B", "jump L96"]
    assert code(program, "L96") == ["load A", "store C", "end"]


def test_a_folded_zero_is_loaded_from_the_first_variable_nothing_writes() -> None:
    # A holds 0 wherever the program goes (nothing names it), and LDV is a byte shorter
    # than LDI; B, which the source loaded, holds 5.
    assert code(after(fold_constants, "C=(KYO)\nB=5\nC=B-5\n"))[-3:] == [
        "load A", "store C", "end"]


@pytest.mark.parametrize(("inside", "outside"), [(12, 13), (-12, -13)])  # MOV's -12..12
def test_a_known_argument_becomes_a_constant_only_within_its_range(inside: int, outside: int
                                                                   ) -> None:
    assert code(after(fold_constants, f"A={inside}; B={outside}; (MOV A,B)"))[-2] == \
        f"call MOV {inside}, B"


# Copy propagation -------------------------------------------------------------------------


def test_a_load_of_what_the_accumulator_holds_goes() -> None:
    assert code(after(propagate_copies, "A=B+1; C=A; D=C")) == [
        "load B", "add 1", "store A", "store C", "store D", "end"]
    assert code(after(propagate_copies, "A=B; B=A; A=A")) == ["load B", "store A", "end"]


def test_a_step_or_a_call_that_changes_the_variable_keeps_the_load() -> None:
    assert code(after(propagate_copies, "A=x; (IMG); B=x; B++; C=B")) == [
        "load x", "store A", "call IMG", "load x", "store B", "inc B", "load B",
        "store C", "end"]


# Dead stores --------------------------------------------------------------------------------


def test_a_store_overwritten_before_any_use_goes_with_its_expression() -> None:
    assert code(after(remove_dead_stores, "A=B+(KYO); A=1; A++; A=2")) == [
        "call KYO", "load 2", "store A", "end"]
    assert code(after(remove_dead_stores, "A=1; A++; A=2")) == ["load 2", "store A", "end"]


def test_stores_seen_by_a_call_or_the_end_stay() -> None:
    assert code(after(remove_dead_stores, "A=1; (TIM 1); A=2")) == [
        "load 1", "store A", "call TIM 1", "load 2", "store A", "end"]


def test_across_a_jump_a_store_is_dead_only_without_lost_line_events() -> None:
    quiet = after(remove_dead_stores, "(TRC 1); A=1\n#10\n:10 A=2")
    assert code(quiet) == ["call TRC 1", "jump L10"]
    traced = after(remove_dead_stores, "(TRC 3); A=1\n#10\n:10 A=2")
    assert code(traced) == ["call TRC 3", "load 1", "store A", "jump L10"]


# Peephole -----------------------------------------------------------------------------------


@pytest.mark.parametrize(("text", "expected"), [
    ("A=A+1", ["inc A"]),
    ("A=A-1", ["dec A"]),
    ("A=A+-2", ["dec A", "dec A"]),
    ("A=A--1", ["inc A"]),
    ("A=A+3", ["load A", "add 3", "store A"]),
    ("A=B+1", ["load B", "add 1", "store A"]),
])
def test_adding_a_small_constant_to_a_variable_becomes_steps(text: str,
                                                             expected: list[str]) -> None:
    assert code(after(rewrite_steps, text)) == [*expected, "end"]


def test_no_step_where_the_accumulator_is_read_after_the_store() -> None:
    block = Block("B0", [Load(A, 1), Operate("+", Imm(1), 1), Store(A, 1), Store(B, 1)],
                  End(1))
    program = rewrite_steps(Program({"B0": block}, "B0"))
    assert program.blocks["B0"].instructions[:3] == [Load(A, 1), Operate("+", Imm(1), 1),
                                                     Store(A, 1)]


# Control flow -------------------------------------------------------------------------------


def test_unreachable_blocks_go_and_a_jump_to_an_end_ends() -> None:
    program = after(simplify_control, "#10\nA=1\n:10 #20\n:20 (END)")
    assert list(program.blocks) == ["B0"]
    assert code(program) == ["end"]


def test_a_block_entered_only_from_the_one_before_joins_it() -> None:
    program = after(simplify_control, "A=1\n:10 B=2\n(MOV 1,1)\n:20 C=3; ?C>#20")
    assert list(program.blocks) == ["B0", "L20", "B1"]
    assert code(program) == ["load 1", "store A", "load 2", "store B", "call MOV 1, 1",
                             "jump L20"]


def jumps(*blocks: tuple[str, list[StepVar], ir.Terminator]) -> Program:
    return Program({block_id: Block(block_id, list[ir.Instruction](instructions), terminator)
                    for block_id, instructions, terminator in blocks}, blocks[0][0])


def test_jumps_to_jumps_are_threaded_only_past_real_jumps() -> None:
    def step(line: int) -> list[StepVar]:
        return [StepVar(A, "++", line)]

    program = simplify_control(jumps(
        ("B0", step(1), Branch(A, ">", "B1", "B2", 1)),
        ("B1", [], Jump("B3", 2)),  # a real jump: B2 lies between
        ("B2", step(3), Jump("B1", 3)),
        ("B3", step(4), Branch(A, "<", "B1", "B4", 4)),
        ("B4", step(5), Jump("B0", 5)),
    ))
    assert ir.validate(program) == []
    assert program.blocks["B0"].terminator == Branch(A, ">", "B3", "B2", 1)
    assert program.blocks["B2"].terminator == Jump("B3", 3)
    assert "B1" not in program.blocks
    fall_through = simplify_control(jumps(
        ("B0", step(1), Branch(A, ">", "B1", "B9", 1)),
        ("B1", [], Jump("B2", 2)),  # falls through to B2: threading would add a jump
        ("B2", step(3), Jump("B0", 3)),
        ("B9", step(4), End(4)),
    ))
    assert fall_through.blocks["B0"].terminator == Branch(A, ">", "B1", "B9", 1)


def test_a_branch_to_one_block_either_way_is_a_jump() -> None:
    program = simplify_control(jumps(
        ("B0", [StepVar(A, "++", 1)], Branch(A, "=", "B1", "B1", 1)),
        ("B1", [StepVar(B, "++", 2)], End(2)),
    ))
    assert list(program.blocks) == ["B0"]
    assert code(program) == ["inc A", "inc B", "end"]


# Superinstructions (-O2) ---------------------------------------------------------------------


def test_a_store_and_the_branch_on_it_fuse() -> None:
    program = after(fuse, "A=(KYO)-5; ?A<#10\n:10 (END)")
    assert code(program) == ["call KYO", "load R sub 5",
                             "store A; if A<0 then L10 else B1"]


def test_a_counted_loop_decrements_and_branches_at_once() -> None:
    program = after(fuse, "@=3\n:10 (TIM 1); @--; ?@>#10\nA=B; B++; ?B>#10")
    assert code(program, "L10")[-1] == "dec @; if @>0 then L10 else B1"
    assert code(program, "B1")[-2:] == ["inc B", "if B>0 then L10 else B2"]  # not --


def test_a_load_and_its_stores_become_moves_when_the_accumulator_is_dead() -> None:
    assert code(after(fuse, "A=B; C=5; D=C; E=A+1")) == [
        "move A, B", "move C, 5", "move D, C", "load A add 1", "store E", "end"]
    stores_then_branch = jumps(("B0", [], End(1)))
    stores_then_branch.blocks["B0"].instructions = [Load(Imm(5), 1), Store(A, 1)]
    stores_then_branch.blocks["B0"].terminator = ir.StoreBranch(B, "=", "B0", "B0", 1)
    fused = fuse(stores_then_branch)
    assert ir.validate(fused) == []
    assert fused.blocks["B0"].instructions == [Load(Imm(5), 1), Store(A, 1)]


def test_a_store_fuses_with_its_branch_past_what_leaves_it_and_the_accumulator() -> None:
    # `P=I` becomes a move, which leaves the accumulator holding I-P for E.
    assert code(after(fuse, "I=(INP 3); E=I-P; P=I; ?E>#20\n:20 (END)")) == [
        "compact call INP 3", "move I, R", "load I sub P", "move P, I",
        "store E; if E>0 then L20 else B1"]
    # Stores of other variables and steps: they leave the accumulator too.
    assert code(fuse(after(propagate_copies, "E=A-1; F=E; @++; ?E>#20\n:20 (END)"))) == [
        "load A sub 1", "store F", "inc @", "store E; if E>0 then L20 else B1"]


@pytest.mark.parametrize("text", [
    "E=A-1; (TIM 1); ?E>#20\n:20 (END)",  # the call sees E, and can fault
    "E=A-1; B=E; ?E>#20\n:20 (END)",  # the move reads E
    "E=A-1; B=C+1; ?E>#20\n:20 (END)",  # the accumulator no longer holds E
])
def test_a_store_stays_apart_from_its_branch_past_a_call_a_read_or_a_new_value(text: str
                                                                               ) -> None:
    assert isinstance(after(fuse, text).blocks["B0"].terminator, Branch)


def test_a_decrement_fuses_with_its_branch_past_what_neither_reads_nor_writes_it() -> None:
    program = after(fuse, "@=3\n:10 @--; A=B+1; C=D; ?@>#10\n(END)")
    assert code(program, "L10") == ["load B add 1", "store A", "move C, D",
                                     "dec @; if @>0 then L10 else B1"]
    for text in ("@=3\n:10 @--; A=@; ?@>#10\n(END)", "@=3\n:10 @--; (TIM 1); ?@>#10\n(END)"):
        assert isinstance(after(fuse, text).blocks["L10"].terminator, Branch)


# Tails merged, the final END left out (-O2) -----------------------------------------------------

IF_ELSE = "A=(KYO); ?A>#20\nB=5; C=7; D=C; #30\n:20 B=6; C=7; D=C\n:30 (MOV B,C); (END)"


def test_a_jumping_block_shares_the_tail_of_the_block_that_falls_through() -> None:
    program = after(merge_tails, IF_ELSE)
    assert list(program.blocks) == ["B0", "B1", "L20", "B2", "L30"]
    assert code(program, "B1") == ["load 5", "store B", "jump B2"]
    assert code(program, "L20") == ["load 6", "store B", "jump B2"]  # laid out before B2
    assert code(program, "B2") == ["load 7", "store C", "load C", "store D", "jump L30"]
    assert [item.line for item in program.blocks["B2"].instructions] == [3] * 4  # L20's


def test_shorter_shared_tails_split_the_longer_one_again() -> None:
    # L21 falls through to :30 ending `D=6; C=7`: B2 shares both, L20 only `C=7`.
    text = ("A=(KYO); ?A>#20\n?A<#21\nD=6; C=7; #30\n:20 D=5; C=7; #30\n:21 B=2; D=6; C=7\n"
            ":30 (MOV C,D); (END)")
    program = after(merge_tails, text)
    assert list(program.blocks) == ["B0", "B1", "B2", "L20", "L21", "B3", "B4", "L30"]
    assert code(program, "B2") == ["jump B3"]
    assert code(program, "L20") == ["load 5", "store D", "jump B4"]
    assert code(program, "L21") == ["load 2", "store B", "jump B3"]  # falls through
    assert code(program, "B3") == ["load 6", "store D", "jump B4"]  # falls through
    assert code(program, "B4") == ["load 7", "store C", "jump L30"]  # falls through


def test_a_tail_that_is_the_whole_falling_block_is_jumped_to_as_it_is() -> None:
    text = "A=(KYO); ?A>#20\nB=1; C=7; #30\n:20 (TIM 1)\n:21 C=7\n:30 (MOV C,C); (END)"
    program = after(merge_tails, text)
    assert list(program.blocks) == list(lowered(text).blocks)
    assert code(program, "B1") == ["load 1", "store B", "jump L21"]


@pytest.mark.parametrize("centre", [1, -1])
def test_a_shared_tail_runs_as_many_instructions_on_either_way(centre: int) -> None:
    script: dict[str, object] = {"KYO": [{"centre": centre, "right": 0, "left": 0}]}
    runs = [run_program(program, script) for program in (lowered(IF_ELSE),
                                                        after(merge_tails, IF_ELSE))]
    assert runs[0] == runs[1]  # the same variables, at the same count


def run_program(program: Program, script: dict[str, object]) -> tuple[list[int], int]:
    """The final variables of the program's code, and the instructions it ran."""
    device = ScriptedDevice(parse_script(script))
    machine = Machine(verify(ilc.encode(generate(program, "t.rob"))), Blocking(device))
    return list(machine.run().variables), machine.executed


@pytest.mark.parametrize("text", [
    # a call: it names its own line when it faults
    "A=(KYO); ?A>#20\n(TIM 1); #30\n:20 (TIM 1)\n:30 (END)",
    # the tail would read the accumulator set before it
    "A=(KYO); ?A>#20\nB=A+5; #30\n:20 B=A+6\n:30 (END)",
    # the falling block jumps too: the jumping block's path would take one jump more
    "A=(KYO)\n:10 ?A>#20\nB=5; #10\n:20 B=5; #10",
    # events: one taken at the jump, now before the tail, would see B before it
    "(TRC 3)\nA=(KYO); ?A>#20\nB=5; #30\n:20 B=5\n:30 (END)\n:96 (END)\n:97 (END)\n"
    ":98 (END)\n:99 (END)",
])
def test_tails_stay_apart_where_merging_would_change_a_line_a_value_or_a_path(text: str
                                                                              ) -> None:
    before = ir_text.format_program(lowered(text))
    assert ir_text.format_program(after(merge_tails, text)) == before


def test_the_final_end_is_left_out_after_an_instruction_of_the_last_block() -> None:
    program = after(leave_out_final_end, "A=(KYO); (MOV A,A); (END)")
    assert code(program)[-1] == "end (past the last instruction)"
    code_names = [instruction.info.name for instruction in
                  verify(ilc.encode(generate(program, "t.rob"))).instructions]
    assert code_names[-1] == "MOV"  # no END: running past the code ends the run
    # An empty last block stays: a jump to it would name the offset past the code.
    kept = after(leave_out_final_end, "A=(KYO); ?A>#10\n(MOV A,A)\n:10 (END)")
    assert code(kept, "L10") == ["end"]


def test_validation_refuses_an_unwritten_end_the_run_would_not_pass_the_code_at() -> None:
    program = jumps(("B0", [StepVar(A, "++", 1)], End(1, written=False)),
                    ("B1", [StepVar(A, "++", 2)], End(2)))
    assert ir.validate(program) == [
        "B0: its end is left unwritten, but the run would not pass the last instruction there"]
    empty = jumps(("B0", [], End(1, written=False)))
    assert len(ir.validate(empty)) == 1


# The pipeline ---------------------------------------------------------------------------------


def test_a_pass_that_breaks_the_ir_is_caught_where_it_runs(monkeypatch: pytest.MonkeyPatch
                                                           ) -> None:
    def breaks(program: Program) -> Program:
        program.blocks[program.entry].instructions.insert(0, Store(X, 1))
        return program

    monkeypatch.setitem(optimize.LEVELS, 1, (breaks, simplify_control))
    with pytest.raises(optimize.OptimizerError, match=r"breaks broke the IR: .*reads acc"):
        optimize.optimize(lowered("A=1"), 1, check=True)
    with pytest.raises(optimize.OptimizerError, match=r"the optimizer broke the IR"):
        optimize.optimize(lowered("A=1"), 1)


def test_level_0_changes_nothing_and_level_1_runs_until_nothing_changes() -> None:
    text = "A=1\n#10\n:10 B=A+1; A=B-2; (MOV A,B)"
    assert ir_text.format_program(optimize.optimize(lowered(text), 0)) == \
        ir_text.format_program(lowered(text))
    # A=1 is dead (A=B-2 follows before any call); then A=B-2 stores 0, which A holds.
    assert code(optimize.optimize(lowered(text), 1)) == [
        "load 2", "store B", "call MOV 0, 2", "end"]


# The accumulator's value reused (issue 14's second round) ------------------------------------


def test_a_folded_value_is_loaded_from_a_variable_that_holds_it() -> None:
    # B=A loads A, which holds 7: LDV A is a byte shorter than LDI 7. C=7 names no
    # variable, but A holds 7 too.
    assert code(after(fold_constants, "A=7; B=A; C=7; D=A+1")) == [
        "load 7", "store A", "load A", "store B", "load A", "store C", "load 8",
        "store D", "end"]


def test_a_zero_is_loaded_from_the_first_variable_that_holds_it_named_or_not() -> None:
    # The flow leaves out the variables nothing names (they hold 0 everywhere), and the
    # load of a 0 still takes the first in the language's order: B, which no statement
    # names (for A=0 too); then A, once A holds 0 and comes first.
    assert code(after(fold_constants, "A=(INP 1); C=0-A; A=0; D=0-C")) == [
        "call INP 1", "load R", "store A", "load B", "sub A", "store C", "load B",
        "store A", "load A", "sub C", "store D", "end"]
    # At a handler's entry nothing is known, a variable nothing names included.
    program = after(fold_constants, "(TRC 2); (MOV 1,1); (END)\n:96 C=0-A; (END)\n")
    assert code(program, program.handlers[96])[:2] == ["load 0", "sub A"]


def test_a_commutative_operation_on_what_the_accumulator_holds_drops_the_load() -> None:
    # d=...; D=D+d: the accumulator holds d, so `load D; add d` is `add D`.
    assert code(after(propagate_copies, "d=(KYO)-1; D=D+d; E=E-d")) == [
        "call KYO", "load R", "sub 1", "store d", "add D", "store D",
        "load E", "sub d", "store E", "end"]  # - is not commutative: E-d stays


def test_a_load_and_the_operation_after_it_become_one_load_and_operate() -> None:
    assert code(after(fuse, "A=B-C; D=B+5; E=(KYO)&C; F=(IMG)>2; G=3-B; H=B+(KYO)")) == [
        "load B sub C", "store A", "load B add 5", "store D",
        "call KYO", "load R and C", "store E", "call IMG", "load R shr 2", "store F",
        # A constant first has no load-and-operate; nor has a call's result second.
        "load 3", "sub B", "store G", "load B", "call KYO", "add R", "store H", "end"]


def test_stores_before_the_operation_become_moves_and_the_load_fuses_after_them() -> None:
    assert code(fuse(after(propagate_copies, "D=(ULT A); E=D-G; ?E<#10\n:10 (END)"))) == [
        "call ULT A", "move D, R", "load R sub G", "store E; if E<0 then L10 else B1"]
    # A store into the loaded variable itself would change what the load reads again.
    program = jumps(("B0", [], End(1)))
    program.blocks["B0"].instructions = [Load(A, 1), Store(B, 1), Store(A, 1),
                                         Operate("-", C, 1), Store(A, 1)]
    assert code(fuse(program)) == ["load A", "store B", "store A", "sub C", "store A", "end"]


def test_the_load_fuses_after_calls_and_steps_from_what_they_leave_as_it_was() -> None:
    # Copy propagation drops the load of I after (LMP 0), which leaves the accumulator:
    # the load comes again from I (R is the last call's only until another call).
    source = "I=(INP 2); (LMP 0); N++; E=I-128; ?E<#10\n:10 (END)"
    assert code(fuse(after(propagate_copies, source))) == [
        "compact call INP 2", "move I, R", "compact call LMP 0", "inc N", "load I sub 128",
        "store E; if E<0 then L10 else B1"]
    assert judge(Run(source, {"INP": {"2": [100]}}), ENGINES, 20_000).problems == []
    # FZI writes s: the load comes again from B, the other variable that holds it; with
    # none left, the stores stay.
    s, inp, fzi = Var("s"), Call("INP", None, (Imm(2),), 1), Call("FZI", None, (), 1)
    program = jumps(("B0", [], End(1)))
    program.blocks["B0"].instructions = [inp, Load(ir.R, 1), Store(s, 1), Store(B, 1), fzi,
                                         Operate("-", Imm(1), 1), Store(C, 1)]
    assert code(fuse(program)) == ["compact call INP 2", "move s, R", "move B, R", "call FZI",
                                   "load B sub 1", "store C", "end"]
    program.blocks["B0"].instructions = [inp, Load(ir.R, 1), Store(s, 1), fzi,
                                         Operate("-", Imm(1), 1), Store(C, 1)]
    assert code(fuse(program)) == ["compact call INP 2", "load R", "store s", "call FZI",
                                   "sub 1", "store C", "end"]


def test_a_load_that_fuses_after_moves_of_later_lines_takes_its_operations_line() -> None:
    # Found by a 50,000-program rl1c fuzz campaign: the reloaded R kept line 2, after the
    # move of line 3, and the line map (lines never decrease) refused the file.
    program = fuse(after(propagate_copies, "G=(IMG)\nD=(ULT A)\nF=D\nE=D-G\n(END)\n"))
    assert ir.validate(program) == []
    block = program.blocks[program.entry]
    assert [(str(item), item.line) for item in block.instructions[-3:]] == [
        ("move F, R", 3), ("load R sub G", 4), ("store E", 4)]


def test_validation_refuses_lines_that_decrease_along_the_layout() -> None:
    program = jumps(("B0", [], End(2)))
    program.blocks["B0"].instructions = [Load(A, 2), Store(B, 1)]
    assert ir.validate(program) == ["B0: line 1 comes after line 2"]


def test_the_load_and_operate_instructions_run_as_their_two_instructions_do() -> None:
    source = "A=(ULT A); B=(ULT B)\nC=A-B; D=A<B; E=(ULT C)>B; F=(ULT C)^5; G=A&12\n"
    script: dict[str, object] = {"ULT A": [-300], "ULT B": [3], "ULT C": [1000, 1000]}
    verdict = judge(Run(source, script), ENGINES, 20_000)
    assert verdict.problems == []
    assert verdict.observations["vm-O2"].document["variables"]["E"] == 125
    # One instruction saved per expression (its load), and per A=(ULT A) (a move); and
    # the final END, left out.
    unoptimized = verdict.observations["vm-O0"].executed
    assert unoptimized is not None
    assert verdict.observations["vm-O2"].executed == unoptimized - 5 - 2 - 1
