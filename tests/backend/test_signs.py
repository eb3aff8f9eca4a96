"""The passes of issue 25 that keep the instruction set, on small programs: branches
decided or negated by the signs earlier branches proved (signs.py), and algebra with
equal operands (copies.py). Each case also runs on every engine, which must agree."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rl1.compiler.analysis import analyze
from rl1.compiler.backend import ir, optimize
from rl1.compiler.backend.copies import cancel_equal_operands
from rl1.compiler.backend.lower import lower
from rl1.compiler.backend.signs import decide_branches
from rl1.compiler.differential import AstEngine, VmEngine, judge
from rl1.compiler.strategies import Run

ENGINES = (AstEngine(), VmEngine(0), VmEngine(1), VmEngine(2))
BUDGET = 20_000


def optimized(source: str, *passes: optimize.Pass) -> ir.Program:
    program = lower(analyze(source).program)
    for run in passes:
        program = run(program)
        assert ir.validate(program) == []
    return program


def terminators(program: ir.Program) -> dict[str, str]:
    return {block.id: str(block.terminator) for block in program}


def kept(branch: str, program: ir.Program) -> bool:
    """Whether a branch is still there as `branch` begins (its fall-through aside)."""
    return any(text.startswith(branch) for text in terminators(program).values())


def instructions(program: ir.Program) -> list[str]:
    return [str(instruction) for block in program for instruction in block.instructions]


def agree(source: str, script: dict[str, object]) -> None:
    assert judge(Run(source, script), ENGINES, BUDGET).problems == []


# What a branch proved ------------------------------------------------------------------

# After `?H=#20` falls through, H is not 0: with H from INP (0..255), it is positive.
PORT_POLL = """H=(INP 3)
?H=#20
?H>#30
(OUT 1,1); (END)
:20 (OUT 2,2); (END)
:30 (OUT 3,3); (END)
"""


def test_a_branch_that_an_earlier_branch_decided_becomes_a_jump() -> None:
    program = optimized(PORT_POLL, decide_branches)
    assert not kept("if H>0 then L30", program)
    assert "jump L30" in terminators(program).values()


@pytest.mark.parametrize("port", [0, 7, 255])
def test_the_decided_program_runs_as_before(port: int) -> None:
    agree(PORT_POLL, {"INP": {"3": [port]}})


def test_a_branch_on_a_sign_the_path_excludes_goes_the_other_way() -> None:
    # On `?A<#20`'s taken edge A is negative: `?A>#30` there can never be taken.
    source = "A=(IMG)\n?A<#20\n(END)\n:20 ?A>#30\n(OUT 1,1); (END)\n:30 (OUT 2,2); (END)\n"
    assert "jump B2" in terminators(optimized(source, decide_branches)).values()
    agree(source, {"IMG": [{"area": -5, "x": 0, "y": 0, "z": 0}]})


def test_a_branch_on_a_variable_of_any_sign_is_kept() -> None:
    source = "A=(IMG)\n?A=#20\n?A>#30\n(END)\n:20 (END)\n:30 (OUT 2,2); (END)\n"
    assert kept("if A>0 then L30", optimized(source, decide_branches))


def test_paths_join_to_the_signs_either_allows() -> None:
    # H is 0 or 5 at :10, so `?H<#30` never jumps; after `?H=#20` it is 5.
    source = (":01 H=(INP 1); ?H=#10\nH=5\n:10 ?H<#30\n?H=#20\n?H>#40\n:20 (END)\n"
              ":30 (OUT 3,3); (END)\n:40 (OUT 4,4); (END)\n")
    branches = terminators(optimized(source, decide_branches))
    assert branches["L10"] == "jump B1"  # past `?H<#30`
    assert "jump L40" in branches.values()
    for port in (0, 9):
        agree(source, {"INP": {"1": [port]}})


# M, a port's data, is 0..255 (B=M has the flow follow its sign).
@pytest.mark.parametrize("value", ["(IMG)&255", "255&(IMG)", "(IMG)&M"])
def test_a_mask_with_the_sign_bit_clear_either_side_proves_not_negative(value: str) -> None:
    source = f"M=(INP 1)\nB=M\nA={value}\n?A<#20\n(OUT 1,1); (END)\n:20 (OUT 2,2); (END)\n"
    assert not kept("if A<0", optimized(source, decide_branches))
    for area in (-1, 300):
        agree(source, {"INP": {"1": [255]}, "IMG": [{"area": area, "x": 0, "y": 0, "z": 0}]})


def test_a_mask_with_the_sign_bit_set_proves_nothing() -> None:
    source = "A=(IMG)&-256\n?A<#20\n(OUT 1,1); (END)\n:20 (OUT 2,2); (END)\n"
    assert kept("if A<0", optimized(source, decide_branches))


def test_a_call_forgets_the_signs_of_the_reserved_variables_it_writes() -> None:
    # x is positive before (IMG), which writes the image's x there.
    source = "x=1\n(IMG)\n?x>#20\n(OUT 1,1); (END)\n:20 (OUT 2,2); (END)\n"
    assert kept("if x>0", optimized(source, decide_branches))


@pytest.mark.parametrize(("value", "taken"), [(-1, True), (0, False), (1, False)])
def test_a_loaded_constant_has_its_own_sign(value: int, taken: bool) -> None:
    source = f"A=(INP 1)\nA={value}\n?A<#20\n(OUT 1,1); (END)\n:20 (OUT 2,2); (END)\n"
    assert terminators(optimized(source, decide_branches))["B0"] == \
        ("jump L20" if taken else "jump B1")


def test_a_step_that_can_wrap_forgets_the_sign() -> None:
    # 32767 + 1 is -32768: a positive variable stepped up may be negative.
    source = "A=(INP 1)\n?A=#20\nA++\n?A<#30\n(END)\n:20 (END)\n:30 (OUT 1,1); (END)\n"
    assert kept("if A<0 then L30", optimized(source, decide_branches))


def test_nothing_is_known_where_a_handler_starts() -> None:
    source = ("(TRC 3); (MOV 1,1); H=(INP 1)\n:10 ?H<#20\n(TIM 1); #10\n:20 (END)\n"
              ":96 ?H<#20\n(MOV 0,0); (END)\n")
    assert kept("if H<0 then L20", optimized(source, decide_branches))


# A negated branch ----------------------------------------------------------------------

# `?N>#20; #10` with N from INP (0..255): not positive is zero, so `?N=#10` falls to :20.
POLL_LOOP = ":10 N=(INP 2)\n?N>#20\n#10\n:20 (OUT 1,N); (END)\n"


@pytest.mark.parametrize("loop", ["10", "30"])  # before and after :20, the block next
def test_a_branch_around_a_jump_is_negated_when_the_signs_allow_it(loop: str) -> None:
    source = POLL_LOOP.replace("10", loop)
    program = optimize.optimize(lower(analyze(source).program), 1, check=True)
    assert terminators(program)[f"L{loop}"] == f"if N=0 then L{loop} else L20"


def test_a_branch_around_a_jump_is_kept_when_the_variable_may_have_any_sign() -> None:
    source = ":10 N=(IMG)\n?N>#20\n#10\n:20 (OUT 1,1); (END)\n"
    program = optimize.optimize(lower(analyze(source).program), 1, check=True)
    assert terminators(program)["L10"] == "if N>0 then L20 else L10"


@pytest.mark.parametrize("readings", [[0, 0, 3], [5], [0, 255]])
def test_the_negated_loop_runs_as_before_in_fewer_instructions(readings: list[int]) -> None:
    script: dict[str, object] = {"INP": {"2": readings}}
    verdict = judge(Run(POLL_LOOP, script), ENGINES, BUDGET)
    assert verdict.problems == []
    executed = {name: verdict.observations[name].executed for name in ("vm-O0", "vm-O1")}
    # -O0 runs `JGT; JMP` on each round that goes on, -O1 one `JZ`.
    assert executed["vm-O1"] is not None and executed["vm-O0"] is not None
    assert executed["vm-O0"] - executed["vm-O1"] >= len(readings) - 1


# Algebra with equal operands -----------------------------------------------------------

@pytest.mark.parametrize(("expression", "value"), [("A-A", 0), ("A^A", 0), ("A&A", None),
                                                   ("A|A", None)])
def test_an_operation_on_the_accumulators_own_value_is_folded(expression: str,
                                                                value: int | None) -> None:
    source = f"A=(INP 1)\nB={expression}\n(OUT 1,B); (END)\n"
    code = instructions(optimized(source, cancel_equal_operands))
    operator = {"-": "sub", "^": "xor", "&": "and", "|": "or"}[expression[1]]
    assert f"{operator} A" not in code
    if value is not None:
        assert f"load {value}" in code
    for port in (0, 77, 255):
        agree(source, {"INP": {"1": [port]}})


def test_an_operation_on_another_variable_is_kept() -> None:
    code = instructions(optimized("A=(INP 1); C=(INP 2)\nB=A-C\n(END)\n",
                                  cancel_equal_operands))
    assert "sub C" in code


def test_a_difference_of_equal_operands_folds_on_at_o1() -> None:
    # `B=A-A+7` is 7 whatever A holds: constant folding carries the 0 on.
    source = "A=(INP 1)\nB=A-A+7\n(OUT 1,B); (END)\n"
    program = optimize.optimize(lower(analyze(source).program), 1, check=True)
    assert "call OUT 1, 7" in instructions(program)
    agree(source, {"INP": {"1": [200]}})


# A way into a branch that the way decides ----------------------------------------------

# `V=6` proves V positive, so the jump from it into `:11 ?V>#12` goes straight to :12;
# the way from `?E>#20`, where V may have any sign, still meets the branch.
CLAMP = """V=(IMG); E=V-6; ?E>#20
:11 ?V>#12
V=1
:12 (MOV V,V); (MOV 0,0); (END)
:20 V=6; #11
"""


def test_a_jump_that_decides_the_branch_it_enters_goes_past_it() -> None:
    program = optimized(CLAMP, decide_branches)
    assert terminators(program)["L20"] == "jump L12"
    assert terminators(program)["L11"] == "if V>0 then L12 else B2"


def test_a_branch_whose_way_decides_the_branch_it_enters_goes_past_it() -> None:
    # On `?A=#20`'s taken edge A is 0, so `:20 ?A>#40` there falls through to B2.
    source = ("A=(INP 1)\n?A=#20\n(OUT 1,1)\n#30\n:20 ?A>#40\n(OUT 2,2); (END)\n"
              ":40 (OUT 3,3); (END)\n:30 (END)\n")
    assert terminators(optimized(source, decide_branches))["B0"] == "if A=0 then B2 else B1"
    for port in (0, 5):
        agree(source, {"INP": {"1": [port]}})


def test_a_branch_whose_way_decides_the_branch_it_enters_goes_past_it_to_any_block() -> None:
    # On `?A=#20`'s taken edge A is 0, so `:20 ?A=#40` there goes to :40, whose block's
    # name sorts after :20's (the ways are threaded whatever order their names sort in).
    source = ("A=(INP 1)\n?A=#20\n(OUT 1,1)\n#30\n:20 ?A=#40\n(OUT 2,2); (END)\n"
              ":40 (OUT 3,3); (END)\n:30 (END)\n")
    assert terminators(optimized(source, decide_branches))["B0"] == "if A=0 then L40 else B1"
    for port in (0, 5):
        agree(source, {"INP": {"1": [port]}})


def test_a_jump_goes_past_the_branch_it_decides_to_a_block_laid_out_before() -> None:
    # From B1 A is not 0, so `:10 ?A=#30` falls through to B2, whatever the blocks' names.
    source = ("A=(INP 1)\n?A=#20\n#10\n:20 (OUT 2,2)\n#10\n:10 ?A=#30\n(OUT 1,1); (END)\n"
              ":30 (END)\n")
    assert terminators(optimized(source, decide_branches))["B1"] == "jump B2"
    for port in (0, 5):
        agree(source, {"INP": {"1": [port]}})


def test_a_way_that_falls_through_into_a_branch_it_decides_is_left_alone() -> None:
    # A jump to :12 in place of falling into `?V>#12` costs as much and 3 bytes more.
    source = "V=(IMG); E=V-6; ?E<#11\nV=6\n:11 ?V>#12\nV=1\n:12 (MOV V,V); (MOV 0,0); (END)\n"
    assert terminators(optimized(source, decide_branches))["B1"] == "jump L11"


@pytest.mark.parametrize("area", [-3, 0, 4, 9])
def test_the_threaded_program_runs_as_before_and_no_longer(area: int) -> None:
    script: dict[str, object] = {"IMG": [{"area": area, "x": 0, "y": 0, "z": 0}]}
    verdict = judge(Run(CLAMP, script), ENGINES, BUDGET)
    assert verdict.problems == []


# Programs made of polls and branch chains, where the flow has signs to work with --------

SOURCES = ("(INP 1)", "(CAM R)", "(IMG)", "N&7", "N-1", "5", "0", "-3")
LABELS = ("10", "20", "30", "40")


@st.composite
def polling_programs(draw: st.DrawFn) -> str:
    """Four labelled polls, each a reading and two or three branches on what was read,
    the last way a jump: `:20 M=(INP 1); ?M=#40; ?M>#10; #30`."""
    lines = ["(TRC 0)"]
    for label, name in zip(LABELS, "NMPQ", strict=True):
        source = draw(st.sampled_from(SOURCES))
        tests = draw(st.lists(st.tuples(st.sampled_from("NMPQ"), st.sampled_from("=<>"),
                                        st.sampled_from(LABELS)), min_size=1, max_size=3))
        branches = "; ".join(f"?{var}{relation}#{target}" for var, relation, target in tests)
        last = draw(st.sampled_from([*(f"#{target}" for target in LABELS), "(END)"]))
        lines.append(f":{label} {name}={source}; {branches}; {last}")
    return "\n".join(lines) + "\n"


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(source=polling_programs(),
       ports=st.lists(st.integers(0, 255), min_size=1, max_size=6),
       pulses=st.lists(st.integers(0, 784), min_size=1, max_size=6),
       areas=st.lists(st.integers(-3, 3), min_size=1, max_size=6))
def test_polls_and_branch_chains_run_alike_at_every_level(
        source: str, ports: list[int], pulses: list[int], areas: list[int]) -> None:
    script: dict[str, object] = {
        "INP": {"1": ports}, "CAM R": pulses,
        "IMG": [{"area": area, "x": 0, "y": 0, "z": 0} for area in areas]}
    assert judge(Run(source, script), ENGINES, BUDGET).problems == []


@pytest.mark.parametrize("fused", [
    ir.StoreBranch(ir.Var("A"), "=", "B1", "B1", 2),  # A = acc, then a branch on it
    ir.DecrementBranch(ir.Var("A"), "B1", "B1", 2),  # A--, then a branch on it
])
@pytest.mark.parametrize(("branched", "decided"), [("A", False), ("B", True)])
def test_a_fused_branch_forgets_what_was_known_of_the_variable_it_writes_alone(
        fused: ir.StoreBranch | ir.DecrementBranch, branched: str, decided: bool) -> None:
    """A and B are 1 before the fused branch, which writes A (x, an image's reading, or
    A - 1, 0): a branch on A after it stays, one on B goes. On IR as -O2's fuse leaves
    it."""
    program = ir.Program({
        "B0": ir.Block("B0", [ir.Load(ir.Imm(1), 1), ir.Store(ir.Var("A"), 1),
                              ir.Store(ir.Var("B"), 1), ir.Call("IMG", None, (), 1),
                              ir.Load(ir.Var("x"), 2)],
                       fused),
        "B1": ir.Block("B1", [], ir.Branch(ir.Var(branched), ">", "B2", "B3", 3)),
        "B2": ir.Block("B2", [], ir.End(4)),
        "B3": ir.Block("B3", [], ir.End(5)),
    }, "B0")
    assert ir.validate(program) == []
    assert kept(f"if {branched}>0", decide_branches(program)) is not decided
