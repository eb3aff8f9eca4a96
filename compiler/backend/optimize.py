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
from .copies import propagate_copies
from .dead_stores import remove_dead_stores
from .peephole import rewrite_steps
from .signs import decide_branches
from .superinstructions import fuse

Pass = Callable[[ir.Program], ir.Program]

# -O1: the passes whose output every format 1.0 reader runs. The control pass comes
# first so that the others see merged blocks, and last so that it removes what they
# made unreachable.
O1_PASSES: tuple[Pass, ...] = (simplify_control, fold_constants, decide_branches,
                               propagate_copies, rewrite_steps, remove_dead_stores,
                               simplify_control)
LEVELS: dict[int, tuple[Pass, ...]] = {0: (), 1: O1_PASSES, 2: O1_PASSES}
# What runs once after a level's passes stop changing the program: -O2's fusion, which
# the other passes need not know.
FINAL_PASSES: dict[int, tuple[Pass, ...]] = {0: (), 1: (), 2: (fuse,)}
MAX_ROUNDS = 8  # a round seldom finds anything after the third


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
    shape = _shape(program)
    for _ in range(MAX_ROUNDS):
        program = _run(passes, program, check, fired)
        before, shape = shape, _shape(program)
        if shape == before:
            break
    program = _run(FINAL_PASSES[level], program, check, fired)
    _validate(program, "the optimizer")
    return program


def _run(passes: tuple[Pass, ...], program: ir.Program, check: bool,
         fired: Callable[[str], None] | None) -> ir.Program:
    for run in passes:
        before = _shape(program) if fired is not None else None  # passes may edit in place
        program = run(program)
        if check:
            _validate(program, run.__name__)
        if fired is not None and _shape(program) != before:
            fired(run.__name__)
    return program


def _shape(program: ir.Program) -> list[tuple[object, ...]]:
    """The whole program as comparable values (instructions are frozen dataclasses)."""
    return [(block.id, *block.instructions, block.terminator) for block in program]


def _validate(program: ir.Program, culprit: str) -> None:
    problems = ir.validate(program)
    if problems:
        raise OptimizerError(f"{culprit} broke the IR: " + "; ".join(problems))
