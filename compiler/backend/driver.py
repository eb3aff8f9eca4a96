"""Compiling one program: source text to the bytes of an .ilc file, or to its IR as text.

The stages run in order (front end, lowering, the optimizer at the level asked for, code
generation) and the first that
refuses the program stops the compilation; its diagnostics say why. Reading the input
and writing the output are the CLI's job.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Literal

from rl1.compiler.analysis import diagnose
from rl1.compiler.frontend.ast import Line
from rl1.compiler.frontend.collector import collector_paused
from rl1.compiler.frontend.diagnostics import Diagnostic, sort_key
from rl1.compiler.frontend.parser import parse_line
from rl1.compiler.frontend.source import first_code_line_after, iter_lines
from rl1.vm import ilc
from rl1.vm.defaults import DEFAULT_LEVEL

from .codegen import CodegenError, generate, line_too_far
from .ir import Program as IrProgram
from .ir import format_program
from .lower import lower
from .optimize import LEVELS, optimize

Emit = Literal["ilc", "ir"]
EMITS: tuple[Emit, ...] = ("ilc", "ir")
OPTIMIZATION_LEVELS = tuple(LEVELS)


@dataclass(frozen=True, slots=True)
class Compilation:
    """Every diagnostic of the program and, when none is an error, the output."""

    diagnostics: list[Diagnostic]
    output: bytes | None


def compile_text(text: str, source_name: str, *, emit: Emit = "ilc",
                 strip_debug: bool = False, level: int = DEFAULT_LEVEL,
                 check: bool = False) -> Compilation:
    """Compile a program at optimization `level` (by default DEFAULT_LEVEL, as
    `rl1c compile`); `source_name` is recorded in the debug section. `check` validates
    the IR after every pass (optimize.optimize)."""
    if emit != "ir" and not strip_debug:
        # Known from the text alone: a long source is refused before it is parsed.
        too_far = first_code_line_after(text, ilc.MAX_LINE)
        if too_far is not None:
            return Compilation([line_too_far(too_far)], None)
    # Checked as `rl1c check` checks, holding no tree; then each line is parsed again as
    # it is lowered, so the tree is never held whole beside the IR (8 MiB of `A=1;...`
    # lines peaked at 155 bytes a source byte with the tree, 95 of them its own).
    diagnostics = diagnose(text)
    if any(diagnostic.is_error for diagnostic in diagnostics):
        return Compilation(diagnostics, None)
    program = optimize(_lowered(text), level, check=check)
    if emit == "ir":
        return Compilation(diagnostics, format_program(program).encode("utf-8"))
    try:
        image = generate(program, source_name, debug=not strip_debug)
    except CodegenError as refused:
        return Compilation(sorted([*diagnostics, refused.diagnostic], key=sort_key), None)
    if image.debug is not None:  # so that `dis` can tell this source from an edited one
        debug = replace(image.debug, source_digest=ilc.source_digest(text))
        image = replace(image, debug=debug)
    return Compilation(diagnostics, ilc.encode(image))


def _lowered(text: str) -> IrProgram:
    """The IR of a program without errors, each line parsed as it is lowered."""
    with collector_paused():  # as parse_program: the objects made all live on
        return lower(_parsed_lines(text))


def _parsed_lines(text: str) -> Iterator[Line]:
    for number, line_text in enumerate(iter_lines(text), start=1):
        yield parse_line(line_text, number)[0]
