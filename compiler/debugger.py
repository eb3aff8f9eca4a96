"""The debugging core: one run of a program on the reference VM, stepped as a debugger
steps it, on the scripted device or the simulator.

A `Session` holds the run. It moves one instruction at a time (`Machine.step(1)`) and
stops where asked: a line breakpoint (with a condition over the variables, written as
the language writes a value: `A<0`, `U-L>0`, `d=0`), a call breakpoint (`IMG`,
`CAM P`), a lost line the program jumps for, a fault, the end; `step_line`,
`step_instruction`, `continue_`, `pause` (from another thread) and `restart`. Between
stops it shows the 53 variables and those the last command changed, the device's state
and the trace so far.

However it is stepped, the run is the one `runner.run` makes, to the bit: the losses
after instruction counts of a sensor script are made where `vm/drive.py`'s `drive` makes
them, and the simulator's time passes where `drive_clocked` lets it pass (after every
`device.slice` instructions), so a stop changes nothing the program or the device sees.
tests/debugger/ holds this with Hypothesis.
"""

from __future__ import annotations

import bisect
import math
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Literal

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.diagnostics import Diagnostic
from rl1.compiler.frontend.parser import parse_line
from rl1.compiler.interpreter import apply, constant, holds
from rl1.vm.defaults import DEFAULT_BUDGET
from rl1.vm.device import Device, DeviceError, FormKey, LineLost, form_name
from rl1.vm.drive import Clocked
from rl1.vm.faults import Fault, FaultKind, RunResult
from rl1.vm.hardware import Blocking
from rl1.vm.language import BUILTINS, VARIABLE_INDEX, VARIABLES, lost_line_handler
from rl1.vm.machine import Machine, State
from rl1.vm.scripted import ScriptedDevice, TraceEntry
from rl1.vm.sim.device import SimDevice, SimEntry
from rl1.vm.sim.motion import heading_degrees
from rl1.vm.verifier import VerifiedProgram, verify


class DebugError(Exception):
    """A breakpoint or condition the session cannot take; the message says what to write."""


def compile_program(text: str, source_name: str, level: int | None = None
                    ) -> bytes | list[Diagnostic]:
    """RL/I source compiled in memory at `level` (None: the default, as `rl1c run`
    compiles it), with its line map; its diagnostics when it has errors."""
    compilation = (compile_text(text, source_name) if level is None
                   else compile_text(text, source_name, level=level))
    return compilation.diagnostics if compilation.output is None else compilation.output


# Values and conditions ----------------------------------------------------------------------------

MAX_EXPRESSION = 1000
"""Characters of a condition, a call breakpoint's name or an evaluated value a client
may give (rl1-dap, the studio): refused whole, a longer one is not quoted in full."""

# Searched for, the value being what comes before: a pattern for the value too
# backtracked over a run of spaces in time quadratic in its length.
_CONDITION = re.compile(r"(?P<relation>[=<>])\s*0\s*$")
_AGAINST_NUMBER = re.compile(r"([=<>])\s*(-?[0-9]+)\s*$")
_RELATIONS: dict[str, ast.Relation] = {"=": "=", ">": ">", "<": "<"}
_CONDITION_HELP = ("write a value of the language compared with 0, as a conditional jump "
                   "tests it: `A<0`, `U-L>0`, `d=0`")
_VALUE_HELP = "write variables and constants joined by operators, as `U-L` or `a<3+c`"


Read = tuple[bool, int]
"""An operand of a value as read: (True, a variable's index) or (False, a constant)."""


@dataclass(frozen=True, slots=True)
class Value:
    """A value as the language writes one: the right side of an assignment, without
    calls (`U-L`, `a<3+c`), read left to right. Its operands are kept as plain numbers,
    not the parser's nodes and spans, which a breakpoint's condition would hold by the
    thousand for the collector to go over."""

    text: str
    first: Read
    rest: tuple[tuple[ast.BinaryOperator, Read], ...]

    def of(self, variables: Sequence[int]) -> int:
        value = _read(self.first, variables)
        for op, operand in self.rest:
            value = apply(op, value, _read(operand, variables))
        return value


def _read(operand: Read, variables: Sequence[int]) -> int:
    variable, number = operand
    return variables[number] if variable else number


@dataclass(frozen=True, slots=True)
class Condition:
    """A value and the relation of `?V=`, `?V>`, `?V<` that it must bear to 0."""

    text: str
    value: Value
    relation: ast.Relation

    def met(self, variables: Sequence[int]) -> bool:
        return holds(self.relation, self.value.of(variables))


def parse_value(text: str, help: str = _VALUE_HELP) -> Value:
    """A value, parsed by the front end as the right side of an assignment; DebugError
    saying what is wrong, and `help`."""
    if not text.strip():
        raise DebugError(f"no value is given: {help}")
    line, diagnostics = parse_line(f"A={text}", 1)
    statements = line.statements
    if diagnostics or line.label is not None or len(statements) != 1 or not isinstance(
            statements[0], ast.Assign):
        reason = diagnostics[0].message if diagnostics else "it is not one value"
        raise DebugError(f"the value `{text.strip()}` cannot be read: {reason}; {help}")
    assign = statements[0]
    for operand in (assign.first, *(step.operand for step in assign.rest)):
        match operand:
            case ast.Call():
                raise DebugError(f"`{text.strip()}` calls a built-in, which would drive the "
                                 "vehicle: use the variables it writes (x, y, w after "
                                 "(IMG)) instead")
            case ast.Const(hex=False, value=number) if not -32768 <= number <= 32767:
                raise DebugError(f"the constant {number} in `{text.strip()}` is outside "
                                 "-32768..32767, the values a variable holds")
    return Value(text.strip(), _as_read(assign.first),
                 tuple((step.op, _as_read(step.operand)) for step in assign.rest))


def _as_read(operand: ast.Operand) -> Read:
    match operand:
        case ast.Var(name=name):
            return (True, VARIABLE_INDEX[name])
        case ast.Const():
            return (False, constant(operand))
        case _:  # parse_value refused calls
            raise AssertionError(operand)


def parse_condition(text: str) -> Condition:
    """A breakpoint's condition: a value compared with 0; DebugError saying what is
    wrong."""
    stripped = text.strip()
    match = _CONDITION.search(stripped)
    other = _AGAINST_NUMBER.search(stripped)
    if match is None and other is not None and other.start() > 0:
        shown, (compared, number) = stripped[:other.start()].rstrip(), other.groups()
        sign = "+" if number.startswith("-") else "-"
        raise DebugError(f"the condition `{stripped}` compares with {number}, and a "
                         f"condition compares with 0 (`<` after a value is a shift): "
                         f"write `{shown}{sign}{number.lstrip('-')}{compared}0`")
    if match is None or not (value_text := stripped[:match.start()].rstrip()):
        raise DebugError(f"the condition `{stripped}` compares nothing with 0: "
                         f"{_CONDITION_HELP}")
    value = parse_value(value_text, _CONDITION_HELP)
    return Condition(stripped, value, _RELATIONS[match["relation"]])


def parse_call(name: str) -> FormKey:
    """A call breakpoint's built-in: `IMG`, or a form of one, `CAM P`, in any case."""
    mnemonic, _, selector = name.strip().upper().partition(" ")
    builtin = BUILTINS.get(mnemonic)
    if builtin is None or mnemonic == "END":
        raise DebugError(f"`{name.strip()}` is no built-in to stop at: give a mnemonic of "
                         "Table 2 or 3, as `IMG`, `MOV`, or a form, as `CAM P`")
    selector = selector.strip()
    if not selector:
        return (mnemonic, None)
    selectors = [form.selector for form in builtin.forms if form.selector is not None]
    if selector not in selectors:
        raise DebugError(f"({mnemonic}) has no form `{selector}`" + (
            f": its forms are {', '.join(selectors)}" if selectors else
            f": write `{mnemonic}` alone"))
    return (mnemonic, selector)


# Stops ---------------------------------------------------------------------------------

Reason = Literal["entry", "step", "breakpoint", "call", "lost-line", "pause", "fault",
                 "end"]


@dataclass(frozen=True, slots=True)
class Stop:
    """Why the run stopped, on which source line (the instruction to run next, or the
    one that faulted), and what to tell a user."""

    reason: Reason
    line: int | None
    text: str = ""


@dataclass(frozen=True, slots=True)
class Binding:
    """A line breakpoint as set: the line asked for and the line with code it stops on
    (None: no code there or after it), its condition, or why it was refused."""

    requested: int
    line: int | None
    condition: Condition | None = None
    message: str = ""

    @property
    def verified(self) -> bool:
        return self.line is not None


class _Watched(Blocking):
    """The VM's hardware, as the runner builds it, noting each lost line taken."""

    def __init__(self, device: Device, line: Callable[[], int | None]) -> None:
        super().__init__(device, line)
        self.taken: list[LineLost] = []

    def take_event(self) -> LineLost | None:
        event = super().take_event()
        if event is not None:
            self.taken.append(event)
        return event


class Session:
    """One program's run, stepped. `image` is an .ilc file's bytes (a line map is needed
    for line breakpoints); `make_device` makes the device afresh for each start, as
    `restart` needs."""

    def __init__(self, image: bytes, make_device: Callable[[], Device],
                 budget: int = DEFAULT_BUDGET) -> None:
        self.program = verify(image)
        self.make_device = make_device
        self.budget = budget
        self.lines = _instruction_lines(self.program)
        self._with_code = sorted({line for line in self.lines if line is not None})
        # The bindings on each line (each condition once; one without a condition,
        # which always stops, alone): a step looks up only the line it enters.
        self.line_breakpoints: dict[int, tuple[Binding, ...]] = {}
        self._conditions: dict[str, Condition | DebugError] = {}  # the last set's, parsed
        self.call_breakpoints: set[FormKey] = set()
        self.stop_on_lost_line = False
        self._pause_requested = False
        self._start()

    # Starting

    def _start(self) -> None:
        self.device = self.make_device()
        self.hardware = _Watched(self.device, lambda: self.machine.current_line())
        self.machine = Machine(self.program, self.hardware, self.budget)
        self.result: RunResult | None = None  # once the run is over
        self._losses: list[int] = []
        # Found once: an isinstance of a Protocol at each instruction was half a step's cost.
        self._clocked = self.device if isinstance(self.device, Clocked) else None
        if isinstance(self.device, ScriptedDevice):
            self._losses = list(self.device.script.instruction_losses)
        elif self._clocked is not None:
            self._clocked.count_instructions(lambda: self.machine.executed)
        self._before = list(self.machine.variables)  # at the last stop
        self._reported = False  # whether a stop was reported here already
        self._lose_lines_due()

    def restart(self) -> Stop:
        """The run again from its start, on a new device; the breakpoints stay."""
        self._start()
        return Stop("entry", self.line)

    # Where the run stands

    @property
    def over(self) -> bool:
        return self.result is not None

    @property
    def line(self) -> int | None:
        """The source line of the instruction to run next (None past the last one)."""
        pc = self.machine.pc
        return self.lines[pc] if pc < len(self.lines) else None

    @property
    def variables(self) -> dict[str, int]:
        return dict(zip(VARIABLES, self.machine.variables, strict=True))

    @property
    def changed(self) -> set[str]:
        """The variables the last command (a step, a continue) changed."""
        return {name for name, before, now in zip(VARIABLES, self._before,
                                                  self.machine.variables, strict=True)
                if before != now}

    @property
    def trace(self) -> list[TraceEntry] | list[SimEntry]:
        device = self.device
        if isinstance(device, ScriptedDevice | SimDevice):
            return device.trace
        return []

    def device_state(self) -> dict[str, object]:
        """What the device is doing now, for people: on the simulator the pose, the
        wheels, the steering, the camera, the tracing mode and the last readings; on the
        scripted device its time, tracing mode, motion and last readings."""
        readings = {_reading_key(entry.call, entry.args): list(entry.result)
                    for entry in self.trace if entry.result is not None}
        match self.device:
            case SimDevice(sim=sim):
                return {
                    "time (s)": round(sim.time, 4),
                    "x (cm)": round(sim.pose.x, 2), "y (cm)": round(sim.pose.y, 2),
                    "heading (degrees)": heading_degrees(sim.pose.heading, 2),
                    "wheel speeds (units)": [round(v, 3) for v in sim.wheel_speeds],
                    "steering (degrees)": round(math.degrees(sim.steering), 2),
                    "camera pan (pulses)": sim.pan,
                    "camera tilt": "down" if sim.tilted_down else "up",
                    "scene": sim.scene,
                    "tracing mode": sim.mode,
                    "motion": None if sim.motion is None else sim.motion.command,
                    "last readings": readings,
                }
            case ScriptedDevice() as scripted:
                return {"time (ms)": scripted.time, "tracing mode": scripted.mode,
                        "motion": scripted.motion, "last readings": readings}
            case _:
                return {}

    # Breakpoints

    def set_line_breakpoints(self, wanted: Iterable[tuple[int, str | None]]
                             ) -> list[Binding]:
        """Replace the line breakpoints: each (line, condition or None), bound to the
        first line at or after it that has code. A condition is parsed once, here; one
        the last call parsed is not parsed again (a client sends every breakpoint of a
        file each time one changes)."""
        with_code = self._with_code
        parsed: dict[str, Condition | DebugError] = {}
        bindings = []
        for requested, text in wanted:
            at = bisect.bisect_left(with_code, requested)
            if at == len(with_code):
                bindings.append(Binding(requested, None, message=(
                    "no code runs on this line or after it" if with_code else
                    "the program has no line map (compiled without debug information): "
                    "compile it again without stripping")))
                continue
            condition = None
            if text:
                if text not in parsed:
                    parsed[text] = self._conditions.get(text) or _parsed_condition(text)
                condition = parsed[text]
            if isinstance(condition, DebugError):
                bindings.append(Binding(requested, None, message=str(condition)))
                continue
            bindings.append(Binding(requested, with_code[at], condition))
        self._conditions = parsed
        self.line_breakpoints = _by_line(bindings)
        return bindings

    def set_call_breakpoints(self, names: Iterable[str]) -> None:
        """Replace the call breakpoints; DebugError naming the first unknown one."""
        self.call_breakpoints = {parse_call(name) for name in names}

    # Moving

    def pause(self) -> None:
        """Stop the command under way at the next instruction (from any thread)."""
        self._pause_requested = True

    def step_instruction(self) -> Stop:
        return self._run(lambda entered: True)

    def step_line(self) -> Stop:
        """Run to the next line entered (by running on to it, or by a jump)."""
        return self._run(lambda entered: entered)

    def continue_(self) -> Stop:
        return self._run(lambda entered: False)

    def _run(self, done: Callable[[bool], bool]) -> Stop:
        self._before = list(self.machine.variables)
        self._pause_requested = False
        if self.over:
            return self._ending()
        if not self._reported and self.machine.executed == 0:
            stop = self._breakpoint(entered=True)
            if stop is not None:
                return self._stopped(stop)
        while True:
            pc = self.machine.pc
            taken = len(self.hardware.taken)
            self._advance()
            if self.over:
                return self._stopped(self._ending())
            entered = self.machine.pc != pc + 1 or self.line != self.lines[pc]
            if self.stop_on_lost_line and len(self.hardware.taken) > taken:
                stop = self._lost_line(self.hardware.taken[-1])
                if stop is not None:
                    return self._stopped(stop)
            stop = self._breakpoint(entered)
            if stop is not None:
                return self._stopped(stop)
            if done(entered):
                return self._stopped(Stop("step", self.line))
            if self._pause_requested:
                return self._stopped(Stop("pause", self.line, "paused"))

    def _stopped(self, stop: Stop) -> Stop:
        self._reported = True
        return stop

    def _advance(self) -> None:
        """One instruction, then what `drive` or `drive_clocked` does at that count."""
        machine = self.machine
        self._reported = False
        if machine.step(1) not in (State.RUNNING, State.WAITING):
            self.result = machine.result
            return
        self._lose_lines_due()
        device = self._clocked
        if device is not None and machine.executed % device.slice == 0:
            try:
                device.catch_up()
            except DeviceError as error:  # a safety stop between calls, as drive_clocked
                device.line = line = machine.current_line()
                device.stop()
                self.result = RunResult(tuple(machine.variables),
                                        Fault(FaultKind.DEVICE, str(error), line))

    def _lose_lines_due(self) -> None:
        """The script's losses after the instruction count reached (drive's order)."""
        device = self.device
        while self._losses and self._losses[0] <= self.machine.executed:
            assert isinstance(device, ScriptedDevice)
            device.lose_line_after(self._losses.pop(0), self.machine.current_line())

    def _breakpoint(self, entered: bool) -> Stop | None:
        line = self.line
        if entered and line is not None:
            for binding in self.line_breakpoints.get(line, ()):
                if binding.condition is None:
                    return Stop("breakpoint", line)
                if binding.condition.met(self.machine.variables):
                    return Stop("breakpoint", line, binding.condition.text)
        pc = self.machine.pc
        if pc < len(self.program.instructions):
            form = self.program.instructions[pc].info.builtin
            if form is not None and (form in self.call_breakpoints
                                     or (form[0], None) in self.call_breakpoints):
                return Stop("call", line, f"({form_name(form)})")
        return None

    def _lost_line(self, event: LineLost) -> Stop | None:
        label = lost_line_handler(event.mode, event.command)
        if label is None:
            return None
        return Stop("lost-line", self.line,
                    f"line lost (mode {event.mode}, {event.command}): jump to :{label}")

    def _ending(self) -> Stop:
        assert self.result is not None
        fault = self.result.fault
        if fault is None:
            return Stop("end", None, "the program ended")
        advice = _BUDGET_ADVICE if fault.kind is FaultKind.BUDGET else ""
        return Stop("fault", fault.line,
                    f"{fault.kind.diagnostic_code}: {fault.message}{advice}")


# What a used-up budget's stop says to do, as rl1c run's help does: the fault's message
# leaves it to the help, which a debugger's stop has no place for.
_BUDGET_ADVICE = ("; if the program should run longer, give it a larger budget; if not, a "
                  "loop that nothing ends is running")


def _parsed_condition(text: str) -> Condition | DebugError:
    try:
        return parse_condition(text)
    except DebugError as error:
        return error


def _by_line(bindings: list[Binding]) -> dict[int, tuple[Binding, ...]]:
    """The verified bindings by the line they stop on: each condition once, in the order
    given, or the first without one alone (it stops whatever the others say)."""
    by_line: dict[int, dict[str | None, Binding]] = {}
    for binding in bindings:
        if binding.line is not None:
            text = None if binding.condition is None else binding.condition.text
            by_line.setdefault(binding.line, {}).setdefault(text, binding)
    return {line: (found[None],) if None in found else tuple(found.values())
            for line, found in by_line.items()}


def _instruction_lines(program: VerifiedProgram) -> list[int | None]:
    """The source line of each instruction (None without a line map), in one pass over
    the line map, which lists code offsets in order."""
    debug = program.image.debug
    if debug is None:
        return [None] * len(program.instructions)
    lines: list[int | None] = []
    entries = debug.lines
    at = -1
    for instruction in program.instructions:
        while at + 1 < len(entries) and entries[at + 1][0] <= instruction.offset:
            at += 1
        lines.append(entries[at][1] if at >= 0 else None)
    return lines


def _reading_key(call: str, args: tuple[int, ...]) -> str:
    """A reading's name in the device state: the call, with the port of an INP."""
    return call if not args else f"{call} {','.join(map(str, args))}"
