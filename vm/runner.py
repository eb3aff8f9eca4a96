"""Running a program by either engine: the stage behind `rl1c run`.

A .rob program is interpreted (engine "ast") or compiled in memory and run on the VM
(engine "vm"); an .ilc file runs on the VM only. Both engines drive the same Device, so
their traces and final variables can be compared.
"""

from __future__ import annotations

from typing import Literal

from rl1.compiler.diagnostics import Diagnostic
from rl1.compiler.driver import compile_text
from rl1.compiler.frontend import analyze

from .device import Device
from .faults import DEFAULT_BUDGET, RunResult
from .interpreter import interpret
from .machine import Machine
from .verifier import verify

Engine = Literal["vm", "ast"]
ENGINES: tuple[Engine, ...] = ("vm", "ast")


def run_source(text: str, source_name: str, device: Device, engine: Engine = "vm",
               budget: int = DEFAULT_BUDGET) -> RunResult | list[Diagnostic]:
    """Run RL/I source by `engine`; the diagnostics instead when it has errors. For the
    VM the compiled bytes go through the verifier, as a file read from disk would."""
    if engine == "ast":
        analysis = analyze(text)
        if analysis.has_errors:
            return analysis.diagnostics
        return interpret(analysis.program, device, budget)
    compilation = compile_text(text, source_name)
    if compilation.output is None:
        return compilation.diagnostics
    return Machine(verify(compilation.output), device, budget).run()


def run_ilc(data: bytes, device: Device, budget: int = DEFAULT_BUDGET) -> RunResult:
    """Run the bytes of an .ilc file on the VM; verifier.VerifyError if they are not
    valid intermediate code."""
    return Machine(verify(data), device, budget).run()
