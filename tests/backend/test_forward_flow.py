"""The forward data flow (forward.py) finds its one greatest fixed point whatever the
order of its visits: constant folding and the signs of branches, run on its worklist,
give what they give on a plain reference that visits every block in layout order, again
and again until nothing changes, gathering what leads into each block from its
predecessors' last visits."""

from __future__ import annotations

import copy
import functools
from collections.abc import Callable, Iterable
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings

from rl1.compiler.analysis import analyze
from rl1.compiler.backend import forward, ir, ir_text
from rl1.compiler.backend.constants import fold_constants
from rl1.compiler.backend.control import simplify_control
from rl1.compiler.backend.lower import lower
from rl1.compiler.backend.signs import decide_branches
from rl1.compiler.strategies import runs


def reference_solve(program: ir.Program, *, entry: Any, handler: Any,
                    combine: Callable[[Any, Any], Any],
                    visit: Callable[[ir.Block, Any], Any],
                    edges: Callable[[ir.Block, Any], Iterable[tuple[ir.BlockId, Any]]]
                    ) -> dict[ir.BlockId, Any]:
    """forward.solve's contract, plainly: every block in layout order until a whole
    sweep changes no visit."""
    predecessors = {block.id: [other for other in program if block.id in other.successors]
                    for block in program}
    handlers = set(program.handlers.values())
    visited: dict[ir.BlockId, Any] = {}
    changed = True
    while changed:
        changed = False
        for block in program:
            states = ([entry] if block.id == program.entry else []) \
                + ([handler] if block.id in handlers else [])
            states += [leaving for pred in predecessors[block.id] if pred.id in visited
                       for target, leaving in edges(pred, visited[pred.id])
                       if target == block.id]
            if not states:
                continue
            result = visit(block, functools.reduce(combine, states))
            if block.id not in visited or visited[block.id] != result:
                visited[block.id] = result
                changed = True
    return visited


def solved_plainly(run_pass: Callable[[ir.Program], ir.Program],
                   program: ir.Program) -> ir.Program:
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(forward, "solve", reference_solve)
        return run_pass(program)


@pytest.mark.parametrize("run_pass", [fold_constants, decide_branches])
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=runs())
def test_the_worklist_finds_what_the_plain_sweeps_find(
        run_pass: Callable[[ir.Program], ir.Program], case: Any) -> None:
    program = simplify_control(lower(analyze(case.source).program))
    expected = solved_plainly(run_pass, copy.deepcopy(program))
    assert ir_text.format_program(run_pass(program)) == ir_text.format_program(expected)


def test_a_loop_is_solved_as_the_plain_sweeps_solve_it() -> None:
    """A loop whose header is reached first from the entry, then from its back edge
    with less known: the fold keeps only what both ways agree on."""
    source = "A=1;B=2\n:10 A=A+1;C=B+3\n?A>#10\n(ROT C)\n"
    program = simplify_control(lower(analyze(source).program))
    expected = ir_text.format_program(solved_plainly(fold_constants, copy.deepcopy(program)))
    folded = ir_text.format_program(fold_constants(program))
    assert folded == expected
    assert "if A>0 then L10" in folded  # A differs on the two ways into :10
    assert "call ROT 5" in folded  # C=B+3 folded: B is 2 on both
