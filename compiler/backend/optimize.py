"""The optimizer: the passes of each level, run over the IR until it stops changing.

spec/optimization.md is the contract (what every pass keeps, the budget invariant);
each pass is a function from IR to IR in a file of its own. `ir.validate` runs after each
one when asked (tests, `rl1c fuzz`), so a pass that breaks the IR is caught where it
does, and after the last one always.
"""

from __future__ import annotations

from collections.abc import Callable

from . import ir
from .constants import fold_constants
from .control import simplify_control
from .copies import cancel_equal_operands, propagate_copies
from .dead_stores import remove_dead_stores
from .final_end import leave_out_final_end
from .peephole import rewrite_steps
from .signs import decide_branches
from .superinstructions import fuse
from .tails import merge_tails

Pass = Callable[[ir.Program], ir.Program]

# -O1: the passes whose output every format 1.0 reader runs. The control pass comes
# first so that the others see merged blocks, and last so that it removes what they
# made unreachable. Algebra comes after constant folding, which gives it work (`0+B` is
# `B`) and carries on what it leaves (`A-A+7` is 7) when it finds any, which is seldom;
# the branches the signs decide come after the passes within blocks, which seldom
# change what that flow finds.
O1_PASSES: tuple[Pass, ...] = (simplify_control, fold_constants, cancel_equal_operands,
                               propagate_copies, rewrite_steps, remove_dead_stores,
                               decide_branches, simplify_control)
LEVELS: dict[int, tuple[Pass, ...]] = {0: (), 1: O1_PASSES, 2: O1_PASSES}
# What runs once after a level's passes stop changing the program, on the instructions
# they leave: -O2's fusion, which the other passes need not know; then the tails merged
# (a tail split off would hide from the passes what its block does), and last the final
# END left out, on the layout the code generator keeps. -O1, the default, which the
# debugger steps by line, keeps every statement's instructions on its own line, and END.
FINAL_PASSES: dict[int, tuple[Pass, ...]] = {
    0: (), 1: (), 2: (fuse, merge_tails, leave_out_final_end)}
MAX_ROUNDS = 8  # a round seldom finds anything after the third

# What lets the rounds skip a pass that could change nothing (compile time: the data
# flows of constant folding and the signs cost the most), each held by a property test
# (tests/backend/test_pass_properties.py). A pass that a second run leaves as it is:
IDEMPOTENT: frozenset[Pass] = frozenset({fold_constants, propagate_copies, rewrite_steps})
# The passes to which a pass's changes never give anything to do: copy propagation keeps
# what every variable and the accumulator hold at every point, and the control flow.
GIVES_NO_WORK_TO: dict[Pass, frozenset[Pass]] = {
    propagate_copies: frozenset({fold_constants, cancel_equal_operands, decide_branches}),
}


class OptimizerError(Exception):
    """A pass broke an invariant of the IR: a bug in the compiler."""


def optimize(program: ir.Program, level: int, *, check: bool = False,
             fired: Callable[[str], None] | None = None) -> ir.Program:
    """The program optimized at `level` (a key of LEVELS). With `check`, `ir.validate`
    runs after every pass (the tests and `rl1c fuzz` ask for it); otherwise once at the
    end, so that a compilation costs little more than at -O0. `fired(name)` after each
    pass that changed the program (`rl1c fuzz --format json` counts them)."""
    passes = LEVELS[level]
    if not passes:
        return program
    program = _to_fixpoint(passes, program, check, fired)
    for pass_ in FINAL_PASSES[level]:
        before = _shape(program) if fired is not None else None  # else no one asks
        program = pass_(program)
        if check:
            _validate(program, pass_.__name__)
        if fired is not None and _shape(program) != before:
            fired(pass_.__name__)
    _validate(program, "the optimizer")
    return program


def _to_fixpoint(passes: tuple[Pass, ...], program: ir.Program, check: bool,
                 fired: Callable[[str], None] | None) -> ir.Program:
    """The passes in rounds until none has work left: a pass has work while the
    program changed since its last run (wherever it stands in the round) in a way that
    could give it some: all passes at first; then, after a change, every pass but those
    IDEMPOTENT and GIVES_NO_WORK_TO rule out. So the rounds stop where the last of them
    settles, not at the end of a round that only says so."""
    shape = _shape(program)
    due = [True] * len(passes)
    for count in range(MAX_ROUNDS * len(passes)):
        index = count % len(passes)
        pass_ = passes[index]
        if not due[index]:
            continue
        due = [flag and other is not pass_ for flag, other in zip(due, passes, strict=True)]
        program, after = _run_one(pass_, program, shape, check, fired)
        if after != shape:
            spared = (GIVES_NO_WORK_TO.get(pass_, frozenset())
                      | ({pass_} if pass_ in IDEMPOTENT else set()))
            due = [flag or other not in spared for flag, other in zip(due, passes, strict=True)]
            shape = after
        # Unchanged, `after` is a second list equal to `shape`: let it go before the next
        # pass runs, so that the rounds hold one shape at a time (a program's size).
        del after
        if not any(due):
            break
    return program


Shape = list[object]


def _run_one(pass_: Pass, program: ir.Program, before: Shape, check: bool,
             fired: Callable[[str], None] | None) -> tuple[ir.Program, Shape]:
    """The program after one pass, and its shape (`before`: its shape before, which
    the caller keeps, as a pass may edit the program in place)."""
    program = pass_(program)
    if check:
        _validate(program, pass_.__name__)
    after = _shape(program)
    if fired is not None and after != before:
        fired(pass_.__name__)
    return program, after


def _shape(program: ir.Program) -> Shape:
    """The whole program as comparable values (instructions are frozen dataclasses): each
    block's id, then its instructions and terminator, in one list. A block's id, the one
    string among them, tells where each block starts, so two programs are alike when
    their shapes are equal. One flat list, since a tuple for each block cost 9 bytes of
    memory a source byte (a program of a branch a line)."""
    shape: Shape = []
    for block in program:
        shape.append(block.id)
        shape.extend(block.instructions)
        shape.append(block.terminator)
    return shape


def _validate(program: ir.Program, culprit: str) -> None:
    problems = ir.validate(program)
    if problems:
        raise OptimizerError(f"{culprit} broke the IR: " + "; ".join(problems))
