"""The fuzzer's generator gives every pass of the highest level work (issue 25): in one
seeded search of `rl1c fuzz` (its programs, and its statistics of the passes that
changed each, as `--format json` reports them), each pass changes a share of the
programs. Before the generator made if-else ways that end alike, equal operands, steps
written as additions, copies, overwritten stores and nested branches on one variable,
tail merging changed none of 51,777 programs and step rewriting 14."""

from __future__ import annotations

from rl1.compiler import fuzz
from rl1.compiler.backend.driver import OPTIMIZATION_LEVELS
from rl1.compiler.backend.optimize import FINAL_PASSES, LEVELS
from rl1.compiler.differential import AstEngine

PROGRAMS = 200
SEED = 1
HIGHEST = max(OPTIMIZATION_LEVELS)
PASSES = sorted({run.__name__ for run in (*LEVELS[HIGHEST], *FINAL_PASSES[HIGHEST])})
# The share of programs each pass must change (issue 25's targets): tail merging's is
# the highest, as the generator makes its shapes on purpose.
LEAST_SHARE = dict.fromkeys(PASSES, 0.01) | {"merge_tails": 0.05}


def test_every_pass_of_the_highest_level_changes_a_share_of_the_generated_programs(
        ) -> None:
    # One engine is enough: the statistics of the passes come from the program alone.
    searched = fuzz.search(fuzz.Search(0, SEED, PROGRAMS, (AstEngine(),), 20_000,
                                       statistics=True))
    assert searched.programs == PROGRAMS and searched.statistics is not None
    fired = searched.statistics.passes
    shares = {name: fired[name] / PROGRAMS for name in PASSES}
    below = {name: share for name, share in shares.items() if share < LEAST_SHARE[name]}
    assert below == {}, shares
