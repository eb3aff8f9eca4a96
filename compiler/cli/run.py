"""Running a program by any engine: the stage behind `rl1c run` and `rl1c sim`.

A .rob program is interpreted (engine "ast") or compiled in memory and run on the
reference VM (engine "vm") or on the C VM of the firmware through ctypes (engine "c",
vm/native.py, which builds it on first use); an .ilc file runs on either VM. Every
engine drives the same scripted device, so their traces and final variables can be
compared. The VMs run in steps (vm/drive.py), which is also how a script's losses after
instruction N are made; the interpreter counts no instructions, so it refuses such a
script. On the scripted device each trace entry gets the source line the engine was
running (ScriptedDevice.locate).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from rl1.compiler.analysis import analyze
from rl1.compiler.backend.driver import compile_text
from rl1.compiler.backend.optimize import DEFAULT_LEVEL
from rl1.compiler.files import read_bounded
from rl1.compiler.frontend.diagnostics import Diagnostic
from rl1.compiler.interpreter import Interpreter
from rl1.vm import ilc
from rl1.vm.device import Device
from rl1.vm.drive import drive
from rl1.vm.faults import DEFAULT_BUDGET, RunResult
from rl1.vm.hardware import Blocking
from rl1.vm.machine import Machine
from rl1.vm.native import NativeMachine, library, load
from rl1.vm.scripted import Script, ScriptedDevice, ScriptError, decode_script
from rl1.vm.verifier import VerifiedProgram, verify

MAX_SCRIPT_BYTES = 16 * 2**20

Engine = Literal["vm", "ast", "c"]
ENGINES: tuple[Engine, ...] = ("vm", "ast", "c")
VmEngine = Literal["vm", "c"]


@dataclass(frozen=True, slots=True)
class Finished:
    """A run to its end: the outcome, the instructions the VM ran (None for the
    interpreter, which counts statements) and the checker's warnings of the source."""

    result: RunResult
    instructions: int | None
    warnings: Sequence[Diagnostic] = ()


def execute_source(text: str, source_name: str, device: Device, engine: Engine = "vm",
                   budget: int = DEFAULT_BUDGET) -> Finished | list[Diagnostic]:
    """Run RL/I source by `engine`; the diagnostics instead when it has errors. For the
    VM it is compiled as `rl1c FILE.rob` compiles it (at the default level), and the
    bytes go through the verifier, as a file read from disk would. ScriptError when the
    interpreter is given losses after instruction counts."""
    if engine == "ast":
        if isinstance(device, ScriptedDevice) and device.script.instruction_losses:
            raise ScriptError("the sensor script loses the line after instruction counts, "
                              "which only the VM counts: run it with --engine vm")
        analysis = analyze(text)
        if analysis.has_errors:
            return analysis.diagnostics
        interpreter = Interpreter(analysis.program, device, budget)
        if isinstance(device, ScriptedDevice):
            device.locate = lambda: interpreter.line
        return Finished(interpreter.run(), None, analysis.diagnostics)
    compilation = compile_text(text, source_name, level=DEFAULT_LEVEL)
    if compilation.output is None:
        return compilation.diagnostics
    finished = execute_program(verify(compilation.output), device, budget,
                               "c" if engine == "c" else "vm", compilation.output)
    return Finished(finished.result, finished.instructions, compilation.diagnostics)


def execute_program(program: VerifiedProgram, device: Device, budget: int = DEFAULT_BUDGET,
                    engine: VmEngine = "vm", data: bytes | None = None) -> Finished:
    """Step a verified program on a VM to its end (on the scripted device, losing the
    line after the instruction counts its script names). The C VM runs `data`, the
    file's own bytes (the image written again when not given); native.BuildError if it
    cannot be built here."""
    machine: Machine | NativeMachine
    if engine == "c":
        machine = NativeMachine(ilc.encode(program.image) if data is None else data,
                                Blocking(device), budget, load(library()))
    else:
        machine = Machine(program, Blocking(device), budget)
    if isinstance(device, ScriptedDevice):
        device.locate = machine.current_line
        return Finished(drive(machine, device), machine.executed)
    return Finished(machine.run(), machine.executed)


def run_source(text: str, source_name: str, device: Device, engine: Engine = "vm",
               budget: int = DEFAULT_BUDGET) -> RunResult | list[Diagnostic]:
    """execute_source's outcome alone."""
    finished = execute_source(text, source_name, device, engine, budget)
    return finished.result if isinstance(finished, Finished) else finished


def run_ilc(data: bytes, device: Device, budget: int = DEFAULT_BUDGET,
            engine: VmEngine = "vm") -> RunResult:
    """Run the bytes of an .ilc file on a VM; verifier.VerifyError if they are not
    valid intermediate code (the Python verifier says why in words, for both VMs);
    native.BuildError if the C VM cannot be built here."""
    return execute_program(verify(data), device, budget, engine, data).result


def load_script(path: str | Path) -> Script:
    """Read and validate a sensor script; SourceError when it cannot be read, ScriptError
    saying what is wrong and where when it is no valid script."""
    data = read_bounded(path, MAX_SCRIPT_BYTES, "a sensor script")
    return decode_script(data, str(path))
