"""The run stage (compiler/runner.py): one entry point for source and .ilc bytes on every
engine, the source lines each engine's adapter gives the device, and what it refuses."""

from __future__ import annotations

import pytest
from support import SAMPLE, SAMPLE_SENSORS

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.frontend.diagnostics import Diagnostic
from rl1.compiler.runner import Finished, load_script, run
from rl1.vm.defaults import Engine
from rl1.vm.scripted import ScriptedDevice
from rl1.vm.sensor_script import LossAfter, Script, ScriptError
from rl1.vm.verifier import VerifyError

TEXT = SAMPLE.read_text(encoding="utf-8")


def finished(outcome: Finished | list[Diagnostic]) -> Finished:
    assert isinstance(outcome, Finished), outcome
    return outcome


def lines(device: ScriptedDevice) -> list[tuple[int, str, int | None]]:
    return [(entry.time, entry.call, entry.line) for entry in device.log]


def test_source_and_its_compiled_bytes_run_alike_on_the_vm_and_the_interpreter() -> None:
    script = load_script(SAMPLE_SENSORS)
    compiled = compile_text(TEXT, "sample.rob").output  # at the default level, as run's
    assert compiled is not None
    devices = [ScriptedDevice(script) for _ in range(3)]
    from_source = finished(run(TEXT, devices[0]))
    from_bytes = run(compiled, devices[1])
    interpreted = finished(run(TEXT, devices[2], engine="ast"))
    assert from_source.result == from_bytes.result == interpreted.result
    assert from_source.instructions == from_bytes.instructions is not None
    assert interpreted.instructions is None
    assert [entry.code for entry in from_source.warnings] == ["W0301"]
    assert from_bytes.warnings == ()
    assert lines(devices[0]) == lines(devices[1]) == lines(devices[2])
    assert {line for _, _, line in lines(devices[0])} >= {2, 4, 40, 43}


def test_a_loss_after_an_instruction_count_is_on_the_line_of_that_instruction() -> None:
    device = ScriptedDevice(Script(losses=(LossAfter(3),)))
    finished(run("(TRC 3)\n(MOV 1,1)\nA=1\nB=2\nC=3\n(MOV 0,0)\n(END)\n"
                 ":96 H=1\n(MOV 0,0)\n(END)\n", device))
    lost = [entry for entry in device.log if entry.call == "LINE LOST"]
    assert [(entry.line, entry.handler) for entry in lost] == [(3, 96)]


def test_source_with_errors_gives_its_diagnostics() -> None:
    engines: tuple[Engine, ...] = ("vm", "ast")
    for engine in engines:
        outcome = run("A=(MOV 1,1)\n", ScriptedDevice(), engine=engine)
        assert isinstance(outcome, list) and all(isinstance(d, Diagnostic) for d in outcome)
        assert any(d.is_error for d in outcome)


def test_what_cannot_run_is_refused() -> None:
    with pytest.raises(VerifyError):
        run(b"RL1\x00 not an .ilc file", ScriptedDevice())
    with pytest.raises(ValueError, match="interpreter runs RL/I source"):
        run(b"", ScriptedDevice(), engine="ast")
    with pytest.raises(ScriptError, match="only the VM counts"):
        run("A=1\n", ScriptedDevice(Script(losses=(LossAfter(1),))), engine="ast")
