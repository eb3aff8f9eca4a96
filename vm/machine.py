"""The reference VM: what every instruction of a verified .ilc program means.

Every other engine (the C VM of the firmware) is held to this one, so it is written to
be read beside spec/ilc.md rather than to be fast: one instruction is fetched, counted
and executed at a time, and each case of `_execute` is a row of the instruction table
(section 8.3) or a rule of section 9. Speed is the C VM's job (`rl1c run --engine c`).

State (section 8.1): the 53 variables (language.VARIABLES order), the accumulator, the
result register R, all 0 at the start, and the program counter, here an index into the
verifier's decoded instructions (jump targets are turned into indices with
`VerifiedProgram.index_of`). Every value is a 16-bit two's complement integer, wrapped
after every operation.

Stepping (section 12): `step(n)` runs at most n instructions and says where the run
stands (RUNNING, WAITING, ENDED or FAULTED); `run` steps to the end. The VM drives the
vehicle through `hardware.Hardware`: a built-in that takes device time is started, then
polled.
"""

from __future__ import annotations

from enum import Enum

from . import isa
from .device import Device, DeviceError, checked, form_name
from .faults import (
    ABORTED_MESSAGE,
    DEFAULT_BUDGET,
    STOP_FAILED,
    Fault,
    FaultKind,
    RunResult,
    argument_range_message,
    budget_message,
    missing_handler_message,
)
from .hardware import Answer, Blocking, Hardware, Status, refusal
from .language import BUILTINS, VARIABLE_INDEX, VARIABLES, lost_line_handler
from .verifier import VerifiedProgram

SLICE = 1 << 20
"""Instructions per step when `run` steps a program to its end."""


class State(Enum):
    """Where a run stands after a step (RL1_RUNNING ... RL1_FAULTED in C)."""

    RUNNING = 0  # the step ran its limit; step again
    WAITING = 1  # a built-in is taking device time; step again to poll it
    ENDED = 2  # (END), or past the last instruction: `result` holds the variables
    FAULTED = 3  # `result` holds the variables and the fault (kind, message, line)


class _Faulted(Exception):
    """A fault of the instruction at hand, raised to the step that runs it."""

    def __init__(self, kind: FaultKind, message: str) -> None:
        self.kind = kind
        self.message = message


# The arithmetic of spec/language.md, sections 6.1 and 7.2. Written apart from the AST
# interpreter's (compiler/interpreter.py) on purpose: the differential tests hold each
# to the other, which a shared function would make a comparison with itself.

def _wrap(value: int) -> int:
    """`value` as a 16-bit two's complement integer."""
    return ((value + 0x8000) & 0xFFFF) - 0x8000


def _shift_left(value: int, count: int) -> int:
    """value << count on 16 bits; a count >= 16 gives 0, a negative one shifts right
    by -count (so -32768 shifts right by 32768)."""
    if count < 0:
        return _shift_right(value, -count)
    if count >= 16:
        return 0
    return _wrap(value << count)


def _shift_right(value: int, count: int) -> int:
    """Arithmetic value >> count; a count >= 16 gives the sign (0 or -1), a negative
    one shifts left by -count."""
    if count < 0:
        return _shift_left(value, -count)
    if count >= 16:
        return -1 if value < 0 else 0
    return value >> count


def evaluate(operator: str, left: int, right: int) -> int:
    """`left operator right` (operator one of isa.ALU_OPERATORS) on 16-bit values: what
    the VM computes, and what the optimizer folds a constant expression to."""
    match operator:
        case "+":
            return _wrap(left + right)
        case "-":
            return _wrap(left - right)
        case "&":
            return left & right
        case "|":
            return left | right
        case "^":
            return left ^ right
        case "<":
            return _shift_left(left, right)
        case _:  # ">"
            return _shift_right(left, right)


class Machine:
    """One run of a verified program on `hardware`, stepped (`step`) or to its end
    (`run`). Its resumable state (spec/ilc.md, section 12.1): the variables, acc, R,
    pc, the instructions executed, the call in progress (`waiting`), whether the run
    has begun, the state and the result."""

    def __init__(self, program: VerifiedProgram, hardware: Hardware,
                 budget: int = DEFAULT_BUDGET) -> None:
        self.program = program
        self.hardware = hardware
        self.budget = budget
        self.variables = [0] * len(VARIABLES)
        self.acc = 0
        self.register = 0  # R, the value of the last call that returns one
        self.pc = 0
        self.executed = 0  # instructions run so far, the one at hand included
        self.waiting: isa.Instruction | None = None  # a call started and not yet done
        self.begun = False
        self.aborting = False  # abort() was called: the next step or event point faults
        self.state = State.RUNNING
        self.result: RunResult | None = None  # once ENDED or FAULTED
        # For each call, the instructions executed up to it, itself included: what the
        # optimizer's budget invariant bounds (spec/optimization.md).
        self.call_counts: list[int] = []

    def run(self) -> RunResult:
        """Step until (END) or a fault: how a host without other work runs a program."""
        while self.step(SLICE) in (State.RUNNING, State.WAITING):
            pass
        assert self.result is not None
        return self.result

    def abort(self) -> None:
        """The emergency stop (rl1_abort in C; spec/ilc.md 12.7), from anywhere, a
        device's callback included: the next step, or the event point under way in one,
        stops the vehicle and ends the run with the fault ABORTED. After the run is over
        it changes nothing."""
        self.aborting = True

    def step(self, limit: int) -> State:
        """Run at most `limit` instructions (0 or more) and say where the run stands.
        The first step begins the run; a call in progress is polled first, once."""
        if self.state in (State.ENDED, State.FAULTED):
            return self.state
        try:
            if not self.begun:
                self._begin()
            if self.aborting:
                return self._fault(FaultKind.ABORTED, ABORTED_MESSAGE, self._line_at_hand())
            if self.waiting is not None and not self._poll(self.waiting):
                return State.WAITING
            for _ in range(limit):
                self._execute_next()
                if self.state is not State.RUNNING:
                    return self.state
        except _Faulted as fault:
            return self._fault(fault.kind, fault.message)
        except DeviceError as error:
            return self._fault(FaultKind.DEVICE, str(error))
        return State.RUNNING

    def _line_at_hand(self) -> int | None:
        """Between steps: the source line of the call in progress, or else of the next
        instruction."""
        return self.current_line() if self.waiting is not None else self._line_of(self.pc)

    def current_line(self) -> int | None:
        """The source line of the instruction before pc: while an instruction runs, the
        one at hand (the call under way, the one that faulted); None at index 0."""
        return self._line_of(self.pc - 1) if self.pc > 0 else None

    def _line_of(self, index: int) -> int | None:
        """The source line of the instruction at `index`: None past the last one, or
        without a line map."""
        debug = self.program.image.debug
        instructions = self.program.instructions
        if debug is None or index == len(instructions):
            return None
        return debug.line_at(instructions[index].offset)

    # One instruction

    def _execute_next(self) -> None:
        """Fetch the instruction at pc, count it, and execute it (section 8.3)."""
        instructions = self.program.instructions
        if self.pc == len(instructions):  # past the last instruction: (END), not counted
            self._end()
            return
        instruction = instructions[self.pc]
        self.pc += 1
        self.executed += 1
        self._execute(instruction)

    def _execute(self, instruction: isa.Instruction) -> None:
        v = self.variables
        operands = instruction.operands
        match instruction.info.name:
            case "END":
                self._end()
            case "LDV":
                self.acc = v[operands[0]]
            case "LDI":
                self.acc = operands[0]
            case "LDR":
                self.acc = self.register
            case "STV":
                v[operands[0]] = self.acc
            case "INC":
                v[operands[0]] = _wrap(v[operands[0]] + 1)
            case "DEC":
                v[operands[0]] = _wrap(v[operands[0]] - 1)
            case "MOVV":
                v[operands[0]] = v[operands[1]]
            case "MOVI" | "MOVB":
                v[operands[0]] = operands[1]
            case "MOVR":
                v[operands[0]] = self.register
            case "JMP":
                self._jump(operands[0])
            case "JZ":
                if v[operands[0]] == 0:
                    self._jump(operands[1])
            case "JGT":
                if v[operands[0]] > 0:
                    self._jump(operands[1])
            case "JLT":
                if v[operands[0]] < 0:
                    self._jump(operands[1])
            case "DJGT":
                v[operands[0]] = _wrap(v[operands[0]] - 1)
                if v[operands[0]] > 0:
                    self._jump(operands[1])
            case "SJZ":
                v[operands[0]] = self.acc
                if v[operands[0]] == 0:
                    self._jump(operands[1])
            case "SJGT":
                v[operands[0]] = self.acc
                if v[operands[0]] > 0:
                    self._jump(operands[1])
            case "SJLT":
                v[operands[0]] = self.acc
                if v[operands[0]] < 0:
                    self._jump(operands[1])
            case _ if instruction.info.builtin is not None:
                self._call(instruction)
            case _:  # the operators, and the loads-and-operate of format 1.2
                left, right = self._operator_operands(instruction)
                self.acc = evaluate(isa.ALU_OPERATORS[instruction.info.opcode & 7],
                                    left, right)

    def _operator_operands(self, instruction: isa.Instruction) -> tuple[int, int]:
        """The values an operator instruction combines: its opcode is a block's base
        (the kinds of its operands) plus the operator's index (isa.py)."""
        v = self.variables
        operands = instruction.operands
        match instruction.info.opcode & ~7:
            case isa.ALU_VAR:
                return self.acc, v[operands[0]]
            case isa.ALU_IMM:
                return self.acc, operands[0]
            case isa.ALU_RESULT:
                return self.acc, self.register
            case isa.COMPUTE_VAR_VAR:
                return v[operands[0]], v[operands[1]]
            case isa.COMPUTE_VAR_IMM:
                return v[operands[0]], operands[1]
            case isa.COMPUTE_RESULT_VAR:
                return self.register, v[operands[0]]
            case _:  # isa.COMPUTE_RESULT_IMM
                return self.register, operands[0]

    # Jumps, calls and lost lines (section 9)

    def _jump(self, target: int) -> None:
        """A jump taken to code offset `target`: the watchdog, then the event point."""
        self._watchdog()
        self.pc = self._event_point(self.program.index_of[target])

    def _watchdog(self) -> None:
        if self.executed > self.budget:
            raise _Faulted(FaultKind.BUDGET, budget_message(self.budget))

    def _event_point(self, resume: int) -> int:
        """Where the program goes on from a point where a lost line is taken: the
        handler Table 4 names for a pending event, or else `resume`."""
        if self.aborting:
            raise _Faulted(FaultKind.ABORTED, ABORTED_MESSAGE)
        event = self.hardware.take_event()
        if event is None:
            return resume
        label = lost_line_handler(event.mode, event.command)
        if label is None:  # the mode calls for no jump
            return resume
        handler = self.program.image.handlers.get(label)
        if handler is None:
            raise _Faulted(FaultKind.MISSING_HANDLER,
                           missing_handler_message(event.mode, event.command, label))
        return self.program.index_of[handler]

    def _call(self, instruction: isa.Instruction) -> None:
        """A call's effects, in the order of section 9: the watchdog, the arguments,
        the device (one call, or a start then polls); the rest is `_done`'s."""
        self._watchdog()
        self.call_counts.append(self.executed)
        form = instruction.info.builtin
        assert form is not None
        args = self._arguments(instruction)
        if BUILTINS[form[0]].waits:
            started = self.hardware.start(form, args)
            if started.status is not Status.OK:
                raise DeviceError(refusal(started))
            self.waiting = instruction
            if not self._poll(instruction):
                self.state = State.WAITING
        else:
            self._done(instruction, self.hardware.call(form, args))

    def _arguments(self, instruction: isa.Instruction) -> tuple[int, ...]:
        """The call's argument values, left to right; a variable's value outside its
        parameter's range is a fault."""
        form = instruction.info.form
        assert form is not None
        values = []
        for param, arg in zip(form.params, instruction.args, strict=True):
            if not arg.is_var:  # the verifier checked its range
                values.append(arg.value)
                continue
            value = self.variables[arg.value]
            if not param.low <= value <= param.high:
                assert instruction.info.builtin is not None
                raise _Faulted(FaultKind.ARGUMENT_RANGE, argument_range_message(
                    param.name, form_name(instruction.info.builtin), value, arg.value,
                    param.low, param.high))
            values.append(value)
        return tuple(values)

    def _poll(self, instruction: isa.Instruction) -> bool:
        """Poll the call in progress: False while it is busy; done, `_done`."""
        answer = self.hardware.poll()
        if answer.status is Status.BUSY:
            return False
        self.waiting = None
        self.state = State.RUNNING
        self._done(instruction, answer)
        return True

    def _done(self, instruction: isa.Instruction, answer: Answer) -> None:
        """The end of a call: an answer other than OK faults; what it read is checked,
        then written (the reserved variables, then R); then the event point."""
        if answer.status is not Status.OK:  # BUSY too: only a poll may answer it
            raise DeviceError(refusal(answer))
        form = instruction.info.form
        assert form is not None and instruction.info.builtin is not None
        outcome = checked(instruction.info.builtin, answer.outcome)
        for name, value in zip(form.writes, outcome.writes, strict=True):
            self.variables[VARIABLE_INDEX[name]] = value
        if form.returns_value:
            assert outcome.result is not None
            self.register = outcome.result
        self.pc = self._event_point(self.pc)

    # The run's start and end (section 12.3)

    def _begin(self) -> None:
        self.begun = True
        answer = self.hardware.begin()
        if answer.status is not Status.OK:
            raise DeviceError(refusal(answer))
        self.hardware.take_event()  # a loss from before the program is not its own

    def _end(self) -> None:
        self.state = State.ENDED  # before `end`, so that a fault does not call it again
        answer = self.hardware.end()
        if answer.status is not Status.OK:
            raise DeviceError(refusal(answer))
        self.result = RunResult(tuple(self.variables))

    def _fault(self, kind: FaultKind, message: str, line: int | None = None) -> State:
        """Stop the vehicle, tell the device the program is over (unless the fault came
        from telling it), and describe the fault at the instruction at hand (`line`
        when given, else the instruction run last)."""
        stopped = self.hardware.stop()
        if stopped.status is not Status.OK:
            message += STOP_FAILED + refusal(stopped)
        if self.state is not State.ENDED:
            self.hardware.end()  # the fault is reported whatever the end answers
        self.state = State.FAULTED
        self.result = RunResult(tuple(self.variables),
                                Fault(kind, message, line or self.current_line()))
        return State.FAULTED


def run(program: VerifiedProgram, device: Device, budget: int = DEFAULT_BUDGET) -> RunResult:
    """Run a verified program on a blocking `device`."""
    return Machine(program, Blocking(device), budget).run()
