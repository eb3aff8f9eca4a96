"""Running a program by any engine: the run stage behind `rl1c run` and `rl1c sim`.

One entry point, `run`: RL/I source is interpreted (engine "ast") or compiled in memory
at the default level, as `rl1c FILE.rob` compiles it, and run on the reference VM
(engine "vm") or on the C VM of the firmware through ctypes (engine "c", vm/native.py,
built on first use); the bytes of an .ilc file run on either VM. Every engine drives the
device it is given, through the adapter that tells the device the source line of each
call (vm/device.py's `perform` for the interpreter, hardware.Blocking for the VMs).

The VMs run in steps (vm/drive.py), which is also how a sensor script's losses after
instruction N are made, and how the simulator's time passes between calls; the
interpreter counts no instructions, so it refuses such a script, and on the simulator
each statement it runs takes one instruction's time.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import overload

from rl1.compiler.analysis import analyze
from rl1.compiler.backend.driver import compile_text
from rl1.compiler.files import read_bounded
from rl1.compiler.frontend.diagnostics import Diagnostic
from rl1.compiler.interpreter import Interpreter
from rl1.vm.defaults import DEFAULT_BUDGET, Engine
from rl1.vm.device import Device
from rl1.vm.drive import Clocked, drive, drive_clocked
from rl1.vm.faults import RunResult
from rl1.vm.hardware import Blocking
from rl1.vm.machine import Machine
from rl1.vm.native import NativeMachine, library, load
from rl1.vm.scripted import ScriptedDevice
from rl1.vm.sensor_script import Script, ScriptError, decode_script
from rl1.vm.verifier import verify

MAX_SCRIPT_BYTES = 16 * 2**20


@dataclass(frozen=True, slots=True)
class Finished:
    """A run to its end: the outcome, the instructions the VM ran (None for the
    interpreter, which counts statements) and the checker's warnings of the source."""

    result: RunResult
    instructions: int | None
    warnings: Sequence[Diagnostic] = ()


@overload
def run(program: str, device: Device, *, engine: Engine = "vm", budget: int = DEFAULT_BUDGET,
        source_name: str = "program.rob") -> Finished | list[Diagnostic]: ...
@overload
def run(program: bytes, device: Device, *, engine: Engine = "vm",
        budget: int = DEFAULT_BUDGET, source_name: str = "program.rob") -> Finished: ...
def run(program: str | bytes, device: Device, *, engine: Engine = "vm",
        budget: int = DEFAULT_BUDGET, source_name: str = "program.rob"
        ) -> Finished | list[Diagnostic]:
    """Run `program` on `device` by `engine` to its end: RL/I source (str, recorded in
    the compiled code as `source_name`), or the bytes of an .ilc file, which only the VMs
    run. The source's diagnostics instead when it has errors.

    Raises verifier.VerifyError when the bytes are not valid intermediate code (the
    Python verifier says why in words, for both VMs), native.BuildError when the C VM
    cannot be built here, ScriptError when the interpreter is given a script with
    losses after instruction counts."""
    if isinstance(program, bytes):
        if engine == "ast":
            raise ValueError("the interpreter runs RL/I source, not .ilc bytes")
        return _on_vm(program, device, engine, budget)
    if engine == "ast":
        return _interpret(program, device, budget)
    compilation = compile_text(program, source_name)
    if compilation.output is None:
        return compilation.diagnostics
    finished = _on_vm(compilation.output, device, engine, budget)
    return Finished(finished.result, finished.instructions, compilation.diagnostics)


def _interpret(text: str, device: Device, budget: int) -> Finished | list[Diagnostic]:
    if isinstance(device, ScriptedDevice) and device.script.instruction_losses:
        raise ScriptError("the sensor script loses the line after instruction counts, "
                          "which only the VM counts: run it with --engine vm")
    analysis = analyze(text)
    if analysis.has_errors:
        return analysis.diagnostics
    interpreter = Interpreter(analysis.program, device, budget)
    if isinstance(device, Clocked):  # the interpreter's statements take its time
        device.count_instructions(lambda: interpreter.steps)
    return Finished(interpreter.run(), None, analysis.diagnostics)


def _on_vm(data: bytes, device: Device, engine: Engine, budget: int) -> Finished:
    """Step the .ilc file `data` on a VM to its end (on the scripted device, losing the
    line after the instruction counts its script names)."""
    program = verify(data)  # before the C VM is built: a bad file is refused the same way
    # The adapter asks the machine for the line of each call, once the machine exists.
    hardware = Blocking(device, lambda: machine.current_line())
    machine: Machine | NativeMachine
    if engine == "c":
        machine = NativeMachine(data, hardware, budget, load(library()))
    else:
        machine = Machine(program, hardware, budget)
    if isinstance(device, ScriptedDevice):
        return Finished(drive(machine, device), machine.executed)
    if isinstance(device, Clocked):
        return Finished(drive_clocked(machine, device), machine.executed)
    return Finished(machine.run(), machine.executed)


def load_script(path: str | Path) -> Script:
    """Read and validate a sensor script; SourceError when it cannot be read, ScriptError
    saying what is wrong and where when it is no valid script."""
    data = read_bounded(path, MAX_SCRIPT_BYTES, "a sensor script")
    return decode_script(data, str(path))
