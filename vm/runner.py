"""Running a program by either engine: the stage behind `rl1c run`.

A .rob program runs on the interpreter (engine "ast") or is compiled in memory and run on
the VM (engine "vm"); an .ilc file runs on the VM only. Both engines drive the same
Device, so their traces and final variables can be compared.
"""

from __future__ import annotations

from typing import Literal

from rl1.compiler import ast
from rl1.compiler.codegen import generate
from rl1.compiler.lower import lower

from . import ilc
from .device import Device
from .faults import DEFAULT_BUDGET, RunResult
from .interpreter import interpret
from .machine import Machine
from .verifier import VerifiedProgram, verify

Engine = Literal["vm", "ast"]
ENGINES: tuple[Engine, ...] = ("vm", "ast")


def compile_program(program: ast.Program, source_name: str) -> VerifiedProgram:
    """The verified image of a program the checker accepted, built in memory (the
    bytes go through the verifier, as a file read from disk would). Raises
    codegen.CodeTooLarge when the code does not fit."""
    return verify(ilc.encode(generate(lower(program), source_name)))


def run_program(program: ast.Program, source_name: str, device: Device, engine: Engine,
                budget: int = DEFAULT_BUDGET) -> RunResult:
    """Run a checked program by `engine`."""
    if engine == "ast":
        return interpret(program, device, budget)
    return Machine(compile_program(program, source_name), device, budget).run()
