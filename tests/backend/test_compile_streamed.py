"""`compile_text` lowers each line of a source past driver.TREE_CHARACTERS as the check
parses it, holding no tree: its output, the .ilc bytes and the IR, and its diagnostics
are those of the compile on a whole tree (`analyze`, then `lower` of the tree), which
shorter sources take, for the examples, bench/corpus, bench/unseen and generated
programs, those with errors among them (each compiled streamed here, whatever its
length)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rl1.compiler import analysis
from rl1.compiler.backend import driver
from rl1.compiler.backend.codegen import CodegenError, generate
from rl1.compiler.backend.driver import EMITS, OPTIMIZATION_LEVELS, Compilation, Emit
from rl1.compiler.backend.ir_text import format_program
from rl1.compiler.backend.lower import lower
from rl1.compiler.backend.optimize import optimize
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import sort_key
from rl1.compiler.strategies import checked_programs, programs
from rl1.vm import ilc

ROOT = Path(__file__).resolve().parents[2]
FILES = [*sorted((ROOT / "examples").glob("*.rob")),
         *sorted((ROOT / "bench" / "corpus").glob("*.rob")),
         *sorted((ROOT / "bench" / "unseen").glob("*.rob"))]


def compiled_on_the_tree(text: str, emit: Emit, level: int) -> Compilation:
    """The compile as it was before the lines were lowered as they are checked."""
    checked = analysis.analyze(text)
    if checked.has_errors:
        return Compilation(checked.diagnostics, None)
    program = optimize(lower(checked.program), level)
    if emit == "ir":
        return Compilation(checked.diagnostics, format_program(program).encode("utf-8"))
    try:
        image = generate(program, "same.rob")
    except CodegenError as refused:
        return Compilation(sorted([*checked.diagnostics, refused.diagnostic], key=sort_key),
                           None)
    assert image.debug is not None
    image = replace(image, debug=replace(image.debug, source_digest=ilc.source_digest(text)))
    return Compilation(checked.diagnostics, ilc.encode(image))


def compiled_streamed(text: str, emit: Emit = "ilc", level: int = 1) -> Compilation:
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(driver, "TREE_CHARACTERS", 0)
        return driver.compile_text(text, "same.rob", emit=emit, level=level)


def assert_compiles_as_on_the_tree(text: str) -> None:
    for level in OPTIMIZATION_LEVELS:
        for emit in EMITS:
            assert (compiled_streamed(text, emit, level)
                    == compiled_on_the_tree(text, emit, level)), (emit, level)


@pytest.mark.parametrize("path", FILES, ids=lambda path: path.name)
def test_the_examples_and_benchmarks_compile_as_on_the_tree(path: Path) -> None:
    assert_compiles_as_on_the_tree(path.read_text(encoding="utf-8"))


def test_the_example_sets_are_found() -> None:
    assert {path.parent.name for path in FILES} == {"examples", "corpus", "unseen"}


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(checked_programs(), programs()))
def test_generated_programs_compile_as_on_the_tree(text: str) -> None:
    assert_compiles_as_on_the_tree(text)


@pytest.mark.parametrize("text", [
    ":01 A=1\n:01 B=2\n",  # a label defined twice: the lowering refuses the second
    "#07\nA=1\n",  # a jump to no label: known once every line is checked
    "A=1\n(MOV 1\nB=2\n",  # a syntax error: the lines after it are not lowered
    "A=1 B=2\n",
])
def test_programs_with_errors_give_the_trees_diagnostics_and_no_output(text: str) -> None:
    compilation = compiled_streamed(text)
    assert compilation.output is None and any(d.is_error for d in compilation.diagnostics)
    assert compilation == compiled_on_the_tree(text, "ilc", 1)


def test_the_check_hands_over_each_line_until_one_has_an_error() -> None:
    handed: list[ast.Line] = []
    analysis.diagnose_compactly("A=1\n:02 B=2\n(MOV 1\nC=3\n", handed.append)
    assert [(line.number, len(line.statements)) for line in handed] == [(1, 1), (2, 1)]
    handed.clear()
    analysis.diagnose_compactly("#07\nA=1\n", handed.append)  # E0203: known after the last line
    assert [line.number for line in handed] == [1, 2]


def test_only_a_source_past_tree_characters_is_checked_streamed(
        monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(text: str, each_line: object) -> None:
        raise AssertionError("checked streamed")

    monkeypatch.setattr(analysis, "check_text", refuse)
    short = "A=1\n" * (driver.TREE_CHARACTERS // 4)
    assert driver.compile_text(short, "short.rob").output is not None
    with pytest.raises(AssertionError, match="checked streamed"):
        driver.compile_text(short + "B=2\n", "long.rob")
