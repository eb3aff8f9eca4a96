"""The C VM (vm/c/rl1vm.c) against the reference VM (vm/machine.py), driven from Python
through ctypes (vm/native.py): on every run vector, both its files, and on generated
programs compiled at every optimization level, with generated sensor scripts and with
hardware that fails, answers busy or reads values out of range, the two give the same
variables, fault (kind, message, source line), device trace and number of instructions
executed. The library is built with UBSan, which aborts the run on undefined
behaviour."""

from __future__ import annotations

import ctypes
import json
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT
from support.c_vm import sanitized_library
from support.cli import rl1c
from support.hardware import Relay
from support.ilc import CALLS_WITH_ARGUMENTS
from support.scripts import MOVING_STARTS, scripts

from rl1.compiler.backend.driver import OPTIMIZATION_LEVELS, compile_text
from rl1.compiler.strategies import checked_programs
from rl1.vm import ilc, isa, native
from rl1.vm.device import FormKey, Outcome
from rl1.vm.drive import Stepper, drive
from rl1.vm.faults import FaultKind, RunResult
from rl1.vm.hardware import BUSY, Answer, Blocking, Hardware, Status
from rl1.vm.language import VARIABLES, Feature
from rl1.vm.machine import Machine, State
from rl1.vm.scripted import LossAfter, Script, ScriptedDevice, parse_script
from rl1.vm.verifier import verify


@pytest.fixture(scope="session")
def c_vm(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    return native.load(sanitized_library(tmp_path_factory))


def vectors() -> list[dict[str, object]]:
    found = []
    for path in sorted((ROOT / "spec" / "vectors").glob("*.json")):
        found += json.loads(path.read_text(encoding="ascii")).get("vectors", [])
    return found


VECTORS = vectors()


@dataclass
class Run:
    result: RunResult
    trace: list[object]
    executed: int


def run(machine: Stepper, device: ScriptedDevice) -> Run:
    return Run(drive(machine, device), list(device.trace), machine.executed)


def assert_same_runs(lib: ctypes.CDLL, data: bytes, script: Script, budget: int) -> Run:
    reference_device, c_device = ScriptedDevice(script), ScriptedDevice(script)
    expected = run(Machine(verify(data), Blocking(reference_device), budget), reference_device)
    got = run(native.NativeMachine(data, Blocking(c_device), budget, lib), c_device)
    assert got == expected
    return got


@pytest.mark.parametrize("vector", VECTORS, ids=[str(v["name"]) for v in VECTORS])
def test_every_run_vector_runs_alike(c_vm: ctypes.CDLL, vector: dict[str, object]) -> None:
    script = parse_script(vector["sensors"])
    budget = vector["budget"]
    assert isinstance(budget, int)
    for key in ("ilc", "ilc_stripped"):
        got = assert_same_runs(c_vm, bytes.fromhex(str(vector[key])), script, budget)
        assert got.executed == vector["executed"]


def _compiled(text: str, level: int = 0) -> bytes:
    compiled = compile_text(text, "generated.rob", level=level)
    assert compiled.output is not None, compiled.diagnostics
    return compiled.output


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(MOVING_STARTS), checked_programs(), scripts(),
       st.lists(st.integers(0, 300), max_size=3), st.integers(1, 3000))
def test_generated_programs_run_alike(c_vm: ctypes.CDLL, start: str, text: str,
                                      script: Script, instructions: list[int],
                                      budget: int) -> None:
    losses = script.losses + tuple(LossAfter(count) for count in instructions)
    script = Script(**{**{name: getattr(script, name) for name in Script.__slots__},
                       "losses": losses})
    for level in OPTIMIZATION_LEVELS:
        assert_same_runs(c_vm, _compiled(start + text, level), script, budget)


# Hardware that misbehaves: the same plan for both VMs, one action per callback.
PASS, ERROR, BUSY_TWICE, OUT_OF_RANGE, BUSY_OUT_OF_TURN = range(5)


@dataclass
class Flaky(Relay):
    """Blocking hardware whose k-th callback does what plan[k] says: pass, answer ERROR,
    answer BUSY twice before the answer (a poll), read values out of every range, or
    answer BUSY where only a poll may (any other callback)."""

    plan: list[int]
    calls: int = 0
    busy: int = 0  # BUSY answers still to give
    released: bool = False  # the next poll answers what the device has

    def _action(self) -> int:
        self.calls += 1
        return self.plan[(self.calls - 1) % len(self.plan)] if self.plan else PASS

    def _answer(self, answer: Answer) -> Answer:
        return self._misbehaved(self._action(), answer)

    def _misbehaved(self, action: int, answer: Answer) -> Answer:
        if action == ERROR:
            return Answer(Status.ERROR, message=f"callback {self.calls} fails")
        if action == BUSY_OUT_OF_TURN:
            return BUSY
        if action == OUT_OF_RANGE and answer.status is Status.OK:
            outcome = answer.outcome
            wild = 70000 if outcome.result is None or outcome.result < 0 else -1
            return Answer(Status.OK, Outcome(None if outcome.result is None else wild,
                                             tuple(70000 for _ in outcome.writes)))
        return answer

    def begin(self) -> Answer:
        return self._answer(self.inner.begin())

    def call(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        return self._answer(self.inner.call(form, args))

    def start(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        return self._answer(self.inner.start(form, args))

    def poll(self) -> Answer:
        if self.busy:
            self.busy -= 1
            return BUSY
        if self.released:
            self.released = False
            return self.inner.poll()
        action = self._action()
        if action == BUSY_TWICE:
            self.busy, self.released = 1, True
            return BUSY
        # BUSY from a poll would be no misbehaviour: that action passes here
        answer = self.inner.poll()
        return answer if action == BUSY_OUT_OF_TURN else self._misbehaved(action, answer)

    def stop(self) -> Answer:
        return self._answer(self.inner.stop())

    def end(self) -> Answer:
        return self._answer(self.inner.end())


def _flaky_run(machine: Stepper, device: ScriptedDevice) -> Run:
    return Run(machine.run(), list(device.trace), machine.executed)


@settings(max_examples=100, deadline=None)
@given(st.sampled_from(MOVING_STARTS), checked_programs(max_blocks=3), scripts(),
       st.lists(st.sampled_from((PASS, PASS, PASS, ERROR, BUSY_TWICE, OUT_OF_RANGE,
                                 BUSY_OUT_OF_TURN)),
                max_size=12), st.sampled_from(OPTIMIZATION_LEVELS))
def test_misbehaving_hardware_gives_the_same_faults(c_vm: ctypes.CDLL, start: str, text: str,
                                                    script: Script, plan: list[int],
                                                    level: int) -> None:
    data = _compiled(start + text, level)
    reference_device, c_device = ScriptedDevice(script), ScriptedDevice(script)
    reference: Hardware = Flaky(Blocking(reference_device), plan)
    expected = _flaky_run(Machine(verify(data), reference, 5000), reference_device)
    got = _flaky_run(native.NativeMachine(data, Flaky(Blocking(c_device), plan), 5000, c_vm),
                     c_device)
    assert got == expected


FAILING_SENSORS = parse_script({}, "none.json")  # every sensing call is a device error


@pytest.mark.parametrize("info", CALLS_WITH_ARGUMENTS,
                         ids=[info.name for info in CALLS_WITH_ARGUMENTS])
def test_a_variable_argument_at_either_end_of_its_range(c_vm: ctypes.CDLL,
                                                        info: isa.OpInfo) -> None:
    # Every call, full-width and compact (format 1.3), each parameter given a variable, the
    # first or the last, holding the range's ends, one past them and the i16 ends: within
    # the range the device gets the value, outside it the call faults argument-range, on
    # both VMs alike, stepped whole and an instruction at a time.
    assert info.form is not None
    params = info.form.params
    low_end, high_end = (-0x80, 0x7F) if info.compact else (-0x8000, 0x7FFF)
    constants = [min(max(param.low, low_end), high_end) for param in params]
    load, store, end = (isa.BY_NAME[name] for name in ("LDI", "STV", "END"))
    for index, param in enumerate(params):
        for value in {param.low - 1, param.low, param.high, param.high + 1, -0x8000, 0x7FFF}:
            if not -0x8000 <= value <= 0x7FFF:
                continue
            for variable in (0, len(VARIABLES) - 1):
                args = tuple(isa.Arg(k == index, variable if k == index else constant)
                             for k, constant in enumerate(constants))
                code = (isa.encode(load, (value,)) + isa.encode(store, (variable,))
                        + isa.encode(info, (), args) + isa.encode(end))
                data = ilc.encode(ilc.Image(code, {}, frozenset(Feature)))
                run = assert_same_runs(c_vm, data, FAILING_SENSORS, 100)
                fault = run.result.fault
                out_of_range = not param.low <= value <= param.high
                assert (fault is not None and fault.kind is FaultKind.ARGUMENT_RANGE) == (
                    out_of_range), (info.name, index, value, variable)
                for limit in (0, 1):
                    assert stepped(c_vm, data, limit) == stepped(None, data, limit)


def stepped(lib: ctypes.CDLL | None, data: bytes, limit: int) -> list[object]:
    """Each step's state, instructions run and variables, stepping by 1 and `limit` in
    turn, then the result and the trace; on the C VM, or on the reference VM when `lib`
    is None."""
    device = ScriptedDevice(FAILING_SENSORS)
    machine: Machine | native.NativeMachine = (
        Machine(verify(data), Blocking(device), 100) if lib is None
        else native.NativeMachine(data, Blocking(device), 100, lib))
    steps: list[object] = []
    state = State.RUNNING
    while state in (State.RUNNING, State.WAITING):
        state = machine.step(limit if len(steps) % 2 else 1)
        steps.append((state, machine.executed, tuple(machine.variables)))
    return [*steps, machine.result, list(device.trace)]

def test_a_machine_without_a_compiler_is_told_what_to_do(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
) -> None:
    monkeypatch.setenv("CC", "")
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(native.BuildError, match=r"needs a C compiler.*--engine vm"):
        native.library(tmp_path / "cache")


def test_rl1c_run_engine_c_prints_what_the_reference_prints(
    c_vm: ctypes.CDLL, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    # The sample with its script, from source and from the compiled file: the same trace,
    # variables and exit status as the reference VM (the CLI builds its own library, here
    # into a cache of the test's own).
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    sample, sensors = ROOT / "examples" / "sample.rob", ROOT / "examples" / "sample.sensors.json"
    compiled = tmp_path / "sample.ilc"
    assert rl1c(sample, "-o", compiled).exit_code == 0
    for program in (sample, compiled):
        reference = rl1c("run", program, "--sensors", sensors, "--format", "json")
        native_run = rl1c("run", program, "--sensors", sensors, "--format", "json",
                          "--engine", "c")
        assert (native_run.exit_code, native_run.stdout) == (reference.exit_code,
                                                             reference.stdout)
        assert json.loads(native_run.stdout)["trace"]


def test_rl1c_run_engine_c_without_a_compiler_says_what_to_do(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))  # nothing built there
    monkeypatch.setenv("CC", "")
    monkeypatch.setenv("PATH", str(tmp_path))
    program = tmp_path / "p.rob"
    program.write_text("A=1\n", encoding="utf-8")
    result = rl1c("run", program, "--engine", "c")
    assert result.exit_code == 2
    assert "needs a C compiler" in result.stderr and "Traceback" not in result.output
