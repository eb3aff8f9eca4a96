"""Running a program by any engine: the stage behind `rl1c run`.

A .rob program is interpreted (engine "ast") or compiled in memory and run on the
reference VM (engine "vm") or on the C VM of the firmware through ctypes (engine "c",
vm/native.py, which builds it on first use); an .ilc file runs on either VM. Every
engine drives the same scripted device, so their traces and final variables can be
compared. The VMs run in steps (vm/drive.py), which is also how a script's losses after
instruction N are made; the interpreter counts no instructions, so it refuses such a
script.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from rl1.compiler.analysis import analyze
from rl1.compiler.backend.driver import compile_text
from rl1.compiler.backend.optimize import DEFAULT_LEVEL
from rl1.compiler.files import SourceError, read_bounded
from rl1.compiler.frontend.diagnostics import Diagnostic
from rl1.compiler.interpreter import interpret
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


def run_source(text: str, source_name: str, device: Device, engine: Engine = "vm",
               budget: int = DEFAULT_BUDGET) -> RunResult | list[Diagnostic]:
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
        return interpret(analysis.program, device, budget)
    compilation = compile_text(text, source_name, level=DEFAULT_LEVEL)
    if compilation.output is None:
        return compilation.diagnostics
    return run_ilc(compilation.output, device, budget, engine)


def run_ilc(data: bytes, device: Device, budget: int = DEFAULT_BUDGET,
            engine: VmEngine = "vm") -> RunResult:
    """Run the bytes of an .ilc file on a VM; verifier.VerifyError if they are not
    valid intermediate code (the Python verifier says why in words, for both VMs);
    native.BuildError if the C VM cannot be built here."""
    program = verify(data)
    if engine == "c":
        return run_native(data, device, budget)
    return run_program(program, device, budget)


def run_native(data: bytes, device: Device, budget: int = DEFAULT_BUDGET) -> RunResult:
    """Step verified .ilc bytes on the C VM to their end, as `run_program` does."""
    machine = NativeMachine(data, Blocking(device), budget, load(library()))
    return drive(machine, device) if isinstance(device, ScriptedDevice) else machine.run()


def run_program(program: VerifiedProgram, device: Device,
                budget: int = DEFAULT_BUDGET) -> RunResult:
    """Step a verified program on the VM to its end (on the scripted device, losing the
    line after the instruction counts its script names)."""
    machine = Machine(program, Blocking(device), budget)
    return drive(machine, device) if isinstance(device, ScriptedDevice) else machine.run()


def load_script(path: str | Path) -> Script:
    """Read and validate a sensor script; ScriptError says what is wrong and where."""
    try:
        data = read_bounded(path, MAX_SCRIPT_BYTES, "a sensor script")
    except SourceError as error:
        raise ScriptError(str(error)) from None
    return decode_script(data, str(path))
