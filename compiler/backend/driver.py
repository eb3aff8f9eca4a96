"""Compiling one program: source text to the bytes of an .ilc file, or to its IR as text.

The stages run in order (front end, lowering, the optimizer at the level asked for, code
generation) and the first that
refuses the program stops the compilation; its diagnostics say why. Reading the input
and writing the output are the CLI's job.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

from rl1.compiler.analysis import analyze, diagnose_compactly
from rl1.compiler.frontend.ast import Line
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity, sort_key
from rl1.compiler.frontend.source import first_code_line_after
from rl1.vm import ilc
from rl1.vm.defaults import DEFAULT_LEVEL

from .codegen import CodegenError, generate, line_too_far
from .ir import Program as IrProgram
from .ir_text import format_program
from .lower import Lowering, lower, lower_text
from .optimize import LEVELS, optimize

Emit = Literal["ilc", "ir"]
EMITS: tuple[Emit, ...] = ("ilc", "ir")
OPTIMIZATION_LEVELS = tuple(LEVELS)


TREE_CHARACTERS = 16 * 1024
"""A source of up to this many characters is checked and lowered on its whole tree, which
is faster than the streaming check (Listing 1 at -O0 in 0.8 of the time): its tree and
diagnostics hold at most about 3 MB (16 KiB of `A=s` lines), a fifth of the 16.6 MB
rl1c takes to start."""


BYTES_A_BLOCK = 32
"""A source past TREE_CHARACTERS with more blocks than one for this many characters is
lowered after its check, each line parsed again (lower.lower_text), not as the check
parses it: vehicles' programs have a block for 38 to 45 bytes (examples/)."""


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
    diagnostics, program = _checked_and_lowered(text)
    if program is None:
        return Compilation(diagnostics, None)
    program = optimize(program, level, check=check)
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


def _checked_and_lowered(text: str) -> tuple[list[Diagnostic], IrProgram | None]:
    """The program's diagnostics and, when none is an error, its IR (-O0)."""
    if len(text) <= TREE_CHARACTERS:
        analysis = analyze(text)
        return analysis.diagnostics, None if analysis.has_errors else lower(analysis.program)
    # Checked as `rl1c check` checks, holding no tree, each line lowered as the check
    # parses it: the tree is never held whole beside the IR (8 MiB of `A=1;...` lines
    # peaked at 155 bytes a source byte with the tree, 95 of them its own), and no line
    # is parsed twice.
    # A source of many blocks is lowered after the check instead, its lines parsed
    # again, so that the check's graph and the IR (each some 300 bytes a block) are
    # not held together: 7 bytes a block (`?A=#01` lines) peaked at 90 bytes a
    # source byte so. Its lowering is let go once it has made more blocks than that.
    most_blocks = len(text) // BYTES_A_BLOCK
    lowering: Lowering | None = Lowering()

    def take(line: Line) -> None:
        nonlocal lowering
        if lowering is not None:
            lowering.take(line)
            if lowering.blocks > most_blocks:
                lowering = None

    checked = diagnose_compactly(text, take)
    if any(severity is Severity.ERROR for severity in checked.severities()):
        lowering = None  # of no use: let its IR go before the diagnostics are built
        return list(checked), None
    return list(checked), lower_text(text) if lowering is None else lowering.program()
