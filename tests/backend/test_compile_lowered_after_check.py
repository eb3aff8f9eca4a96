"""A source past driver.TREE_CHARACTERS with more blocks than one for
driver.BYTES_A_BLOCK characters is lowered after its check, each line parsed again
(lower.lower_text), so that the check's graph and the IR are not held together: its
output and diagnostics are those of the compile that lowers each line as the check parses
it, whichever line the lowering is let go at, and errors leave no output either way."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rl1.compiler.backend import driver, ir, lower
from rl1.compiler.backend.driver import EMITS, OPTIMIZATION_LEVELS, Compilation, Emit
from rl1.compiler.strategies import checked_programs, programs


def compiled(text: str, emit: Emit, level: int, bytes_a_block: int) -> tuple[Compilation, bool]:
    """The streamed compile with `bytes_a_block` for driver.BYTES_A_BLOCK, and whether
    the text was lowered after its check."""
    lowered_after: list[str] = []

    def spied(text: str) -> ir.Program:
        lowered_after.append(text)
        return lower.lower_text(text)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(driver, "TREE_CHARACTERS", 0)
        patch.setattr(driver, "BYTES_A_BLOCK", bytes_a_block)
        patch.setattr(driver, "lower_text", spied)
        compilation = driver.compile_text(text, "same.rob", emit=emit, level=level)
    return compilation, bool(lowered_after)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(checked_programs(), programs()), st.integers(0, 40))
def test_lowering_after_the_check_gives_what_lowering_during_it_gives(
        text: str, blocks_kept: int) -> None:
    """1 byte a block: never let go (a line holds a byte at least); the text's length
    over `blocks_kept`, and a byte: let go after fewer than `blocks_kept` blocks (0: at
    the first)."""
    for level in OPTIMIZATION_LEVELS:
        for emit in EMITS:
            during, after_too = compiled(text, emit, level, 1)
            assert not after_too
            late = len(text) // blocks_kept + 1 if blocks_kept else len(text) + 1
            after, _ = compiled(text, emit, level, late)
            assert after == during, (emit, level)


def test_a_source_of_a_block_a_line_is_lowered_after_its_check_and_one_of_long_lines_not(
        ) -> None:
    branches = ":01\n" + "?A=#01\n" * 100
    compilation, after = compiled(branches, "ilc", 1, driver.BYTES_A_BLOCK)
    assert after and compilation.output is not None
    statements = (";".join(["A=1"] * 20) + "\n") * 10
    compilation, after = compiled(statements, "ilc", 1, driver.BYTES_A_BLOCK)
    assert not after and compilation.output is not None


def test_a_program_with_errors_gives_no_output_when_lowered_after_its_check() -> None:
    text = "?A=#01\n" * 50 + ":01 A=1\n:01 B=2\n"  # :01 defined twice
    compilation, _ = compiled(text, "ilc", 1, 1)
    late, _ = compiled(text, "ilc", 1, len(text) + 1)
    assert late.output is None and late == compilation
