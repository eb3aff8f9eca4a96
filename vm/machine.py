"""The reference VM: what every instruction of a verified .ilc program means.

Later implementations (a C VM on the vehicle) must behave as this one does.
State: 53 variables (language.VARIABLES order, all 0 at start), the accumulator, the
result register R (the value of the last value-returning call, 0 at start) and the
program counter. Every value is a 16-bit two's complement integer and every result
wraps; shift counts are signed (see `_shift_left`).

Execution: the instruction at the program counter runs; running off the end of the code
is (END). A lost-line event (hardware.py) is taken at two points only: right after each
call instruction and after each jump taken. Its handler is the label Table 4 names for
the event's tracing mode and command (language.LOST_LINE_RULES).

Stepping (spec/ilc.md, section 12): `step(n)` runs at most n instructions and returns
the State: RUNNING, WAITING (a built-in taking device time was started and has not
answered done), ENDED or FAULTED; `run` steps to the end. The VM drives the vehicle
through `hardware.Hardware`: a built-in that takes device time is started, then polled.

Faults end the run after the device is stopped: a variable argument outside its range,
a lost line whose handler the program lacks, the watchdog's instruction budget used up,
and a device error (faults.py has their exit statuses). The watchdog counts every
instruction run and looks at the count when a jump is taken and before a call runs: the
run faults at the first such point where more than `budget` instructions have run. Every
loop takes a jump, so a runaway program always meets it.

How this implementation is fast enough (bench/vm_speed.py) without hiding the meaning:
- Instructions are decoded once into (op, a, b) tuples; jump targets become instruction
  indices. Operands live in one list of cells: the variables at 0..52, R at 53, then
  the program's immediates; so LDV/LDI/LDR are one load, and each ALU operator one case
  whatever its operand kind.
- The accumulator is kept modulo 2**16 rather than wrapped after every operation: + - &
  | and ^ give the same low 16 bits either way, so it is wrapped only where its value is
  read as a number (a store, a shift) and where it could grow fast (a left shift).
- A statement's run "load; operators; store" (the load may be a load-and-operate of
  format 1.2) is also decoded as one EXPRESSION step at the index of its load. Nothing
  in such a run can fault, call the device or be seen before the store, so running it
  at once means the same; a jump into the middle of it (none comes from the compiler)
  runs the single instructions, which stay in place.
- Instructions are counted by index arithmetic when control leaves a straight run (a
  jump taken, a handler entered, the end), not one by one.
- So a step's limit is not counted down either: where a straight run could pass it, a
  HALT is put in the code at the exact index (`_bound`), and taken out when the run
  leaves; a run that cannot reach the limit costs one comparison at its start.
- A jump looks at the hardware's `pending` event and calls `take_event` only when there
  is one.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from . import isa
from .device import Device, DeviceError, FormKey, LineLost, checked, form_name
from .faults import (
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
from .language import BUILTINS, VARIABLE_INDEX, VARIABLES, Param, lost_line_handler
from .verifier import VerifiedProgram

R_CELL = len(VARIABLES)

SLICE = 1 << 20
"""Instructions per step when `run` steps a program to its end."""

# The operations of the dispatch loop (not opcodes: decoding folds operand kinds).
(LOAD, STORE, ADD, SUB, AND, OR, XOR, SHL, SHR, INC, DEC,
 JUMP, JUMP_ZERO, JUMP_POSITIVE, JUMP_NEGATIVE, CALL, END, EXPRESSION, HALT,
 MOVE, DEC_JUMP_POSITIVE, STORE_JUMP_ZERO, STORE_JUMP_POSITIVE, STORE_JUMP_NEGATIVE,
 COMPUTE) = range(25)
_BOUNDARIES = (JUMP, END)  # where a straight run of instructions surely stops


class State(Enum):
    """Where a run stands after a step (RL1_RUNNING ... RL1_FAULTED in C)."""

    RUNNING = 0  # the step ran its limit; step again
    WAITING = 1  # a built-in is taking device time; step again to poll it
    ENDED = 2  # (END), or past the last instruction: `result` holds the variables
    FAULTED = 3  # `result` holds the variables and the fault (kind, message, line)

_ALU = (ADD, SUB, AND, OR, XOR, SHL, SHR)  # in isa.ALU_OPERATORS order
_ALU_BASES = (isa.ALU_RESULT, isa.ALU_IMM, isa.ALU_VAR)  # highest first
_COMPUTE_BASES = (isa.COMPUTE_VAR_VAR, isa.COMPUTE_VAR_IMM, isa.COMPUTE_RESULT_VAR,
                  isa.COMPUTE_RESULT_IMM)
_SIMPLE = {"STV": STORE, "INC": INC, "DEC": DEC}
_JUMPS = {"JMP": JUMP, "JZ": JUMP_ZERO, "JGT": JUMP_POSITIVE, "JLT": JUMP_NEGATIVE,
          "DJGT": DEC_JUMP_POSITIVE, "SJZ": STORE_JUMP_ZERO, "SJGT": STORE_JUMP_POSITIVE,
          "SJLT": STORE_JUMP_NEGATIVE}


@dataclass(frozen=True, slots=True)
class _CallSite:
    """A call instruction, decoded: its form, its arguments (cell index or constant),
    and the cells its results go to."""

    form: FormKey
    params: tuple[Param, ...]
    args: tuple[isa.Arg, ...]
    writes: tuple[int, ...]
    returns_value: bool
    waits: bool  # started and polled, rather than called


@dataclass(frozen=True, slots=True)
class _Expression:
    """A load, the (operator, cell) steps after it, and the cell stored to."""

    first: int
    steps: tuple[tuple[int, int], ...]
    target: int


class _Faulted(Exception):
    def __init__(self, kind: FaultKind, message: str) -> None:
        self.kind = kind
        self.message = message


def _wrap(value: int) -> int:
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


def _operate(operator: int, left: int, right: int) -> int:
    """`left operator right` for an operation of the dispatch loop (ADD ... SHR), modulo
    2**16 as the accumulator is kept."""
    return evaluate(isa.ALU_OPERATORS[_ALU.index(operator)], left, right)


def evaluate(operator: str, left: int, right: int) -> int:
    """`left operator right` as the VM computes it (operator one of isa.ALU_OPERATORS):
    what the optimizer folds a constant expression to."""
    if operator == "<":
        return _shift_left(left, right)
    if operator == ">":
        return _shift_right(left, right)
    return _wrap({"+": left + right, "-": left - right, "&": left & right,
                  "|": left | right, "^": left ^ right}[operator])


class Machine:
    """One run of a verified program on `hardware`, stepped (`step`) or to its end
    (`run`). Its resumable state: the cells (the variables, R), acc, pc (an instruction
    index), the instructions executed, and the call in progress (`waiting`)."""

    def __init__(self, program: VerifiedProgram, hardware: Hardware,
                 budget: int = DEFAULT_BUDGET) -> None:
        self.program = program
        self.hardware = hardware
        self.budget = budget
        self.cells: list[int] = [0] * (R_CELL + 1)
        self._immediates: dict[int, int] = {}
        self.sites: list[_CallSite] = []
        # The load-and-operate instructions: (first cell, operator, second cell) each.
        self.computes: list[tuple[int, int, int]] = []
        self.code = [self._decode(instruction) for instruction in program.instructions]
        self.code.append((END, 0, 0))  # running off the end is (END)
        self.plain = self.code[:]  # every instruction alone, before EXPRESSION steps
        self.expressions: list[_Expression] = []
        self.fused_at = [-1] * len(self.code)  # the EXPRESSION whose run holds an index
        self._group_expressions()
        self.reach = self._reaches()
        self._saved: list[tuple[int, tuple[int, int, int]]] = []  # what a HALT replaced
        self.handlers = {label: program.index_of[offset]
                         for label, offset in program.image.handlers.items()}
        self.acc = 0
        self.pc = 0
        self.executed = 0  # instructions run so far, the one that faulted included
        self.waiting: _CallSite | None = None
        self.state = State.RUNNING
        self.result: RunResult | None = None  # once ENDED or FAULTED
        self._begun = False
        # For each call, the instructions executed up to it, itself included: what the
        # optimizer's budget invariant bounds (spec/optimization.md).
        self.call_counts: list[int] = []

    # Decoding

    def _immediate(self, value: int) -> int:
        """The cell holding the constant `value`."""
        if value not in self._immediates:
            self._immediates[value] = len(self.cells)
            self.cells.append(value)
        return self._immediates[value]

    def _decode(self, instruction: isa.Instruction) -> tuple[int, int, int]:
        info = instruction.info
        name, operands = info.name, instruction.operands
        if name == "END":
            return (END, 0, 0)
        if name == "LDV":
            return (LOAD, operands[0], 0)
        if name == "LDI":
            return (LOAD, self._immediate(operands[0]), 0)
        if name == "LDR":
            return (LOAD, R_CELL, 0)
        if name in _SIMPLE:
            return (_SIMPLE[name], operands[0], 0)
        if name == "MOVV":
            return (MOVE, operands[0], operands[1])
        if name in ("MOVI", "MOVB"):
            return (MOVE, operands[0], self._immediate(operands[1]))
        if name == "MOVR":
            return (MOVE, operands[0], R_CELL)
        if name in _JUMPS:
            *condition, target = operands
            return (_JUMPS[name], condition[0] if condition else 0,
                    self.program.index_of[target])
        if info.opcode & ~7 in _COMPUTE_BASES:  # load-and-operate: base + operator index
            self.computes.append(self._compute(info.opcode, operands))
            return (COMPUTE, len(self.computes) - 1, 0)
        if info.form is None:  # an ALU instruction: base + operator index
            base = next(base for base in _ALU_BASES if info.opcode >= base)
            op = _ALU[info.opcode - base]
            if base == isa.ALU_VAR:
                return (op, operands[0], 0)
            if base == isa.ALU_IMM:
                return (op, self._immediate(operands[0]), 0)
            return (op, R_CELL, 0)
        form = info.form
        assert info.builtin is not None
        self.sites.append(_CallSite(info.builtin, form.params, instruction.args,
                                    tuple(VARIABLE_INDEX[name] for name in form.writes),
                                    form.returns_value, BUILTINS[info.builtin[0]].waits))
        return (CALL, len(self.sites) - 1, 0)

    def _compute(self, opcode: int, operands: tuple[int, ...]) -> tuple[int, int, int]:
        """A load-and-operate instruction as (first cell, operator, second cell)."""
        base = opcode & ~7
        if base == isa.COMPUTE_VAR_VAR:
            first, second = operands
        elif base == isa.COMPUTE_VAR_IMM:
            first, second = operands[0], self._immediate(operands[1])
        elif base == isa.COMPUTE_RESULT_VAR:
            first, second = R_CELL, operands[0]
        else:
            first, second = R_CELL, self._immediate(operands[0])
        return first, _ALU[opcode - base], second

    def _group_expressions(self) -> None:
        """Put an EXPRESSION step at each load (or load-and-operate) that starts a
        load-operators-store run; its b is the index after the store."""
        code = self.code
        steps: tuple[tuple[int, int], ...]
        for index, (op, a, _) in enumerate(code):
            if op == LOAD:
                first, steps = a, ()
            elif op == COMPUTE:
                first, operator, cell = self.computes[a]
                steps = ((operator, cell),)
            else:
                continue
            end = index + 1
            while code[end][0] in _ALU:
                end += 1
            if code[end][0] == STORE:
                steps += tuple((step[0], step[1]) for step in code[index + 1:end])
                self.expressions.append(_Expression(first, steps, code[end][1]))
                code[index] = (EXPRESSION, len(self.expressions) - 1, end + 1)
                self.fused_at[index + 1:end + 1] = [index] * (end - index)

    def _reaches(self) -> list[int]:
        """For each index, how many instructions a straight run from it runs at most:
        up to and including the next JMP or END (a conditional jump or a handler may
        leave earlier). A step whose limit is further away needs no HALT."""
        reach = [0] * len(self.plain)
        following = 0
        for index in range(len(self.plain) - 1, -1, -1):
            following = 1 if self.plain[index][0] in _BOUNDARIES else following + 1
            reach[index] = following
        return reach

    # Stepping

    def step(self, limit: int) -> State:
        """Run at most `limit` instructions (0 or more) and say where the run stands.
        A call in progress is polled first, once; a call that starts taking device time
        ends the step (WAITING) unless its first poll already answers done."""
        if self.state in (State.ENDED, State.FAULTED):
            return self.state
        if not self._begun:
            self._begun = True
            answer = self.hardware.begin()
            if answer.status is not Status.OK:
                return self._faulted(_Faulted(FaultKind.DEVICE, refusal(answer)), None)
            try:
                self.hardware.take_event()  # a loss from before the program is not its own
            except DeviceError as error:
                return self._faulted(_Faulted(FaultKind.DEVICE, str(error)), None)
        return self._execute(limit)

    def run(self) -> RunResult:
        """Step until (END) or a fault: how a host without other work runs a program."""
        while self.step(SLICE) in (State.RUNNING, State.WAITING):
            pass
        assert self.result is not None
        return self.result

    # The dispatch loop

    def _execute(self, limit: int) -> State:
        code, expressions, budget, reach = self.code, self.expressions, self.budget, self.reach
        cells, sites, computes = self.cells, self.sites, self.computes
        last = len(self.program.instructions)  # the END that running off the end runs
        hardware = self.hardware
        take, divert = hardware.take_event, self._divert
        call_counts = self.call_counts
        acc, pc = self.acc, self.pc  # acc modulo 2**16: see the module's docstring
        start = pc  # where the current straight run of instructions began
        executed = self.executed  # instructions run before `start`
        stop_at = executed + limit
        try:
            if self.waiting is not None:
                if not self._finish(self.waiting, hardware.poll()):
                    return State.WAITING
                self.waiting = None
                self.state = State.RUNNING
                pc = start = divert(take(), pc)
            check = self._bound(pc, executed, stop_at)
            while True:
                op, a, b = code[pc]
                pc += 1
                if op == EXPRESSION:
                    expression = expressions[a]
                    acc = cells[expression.first]
                    for operator, cell in expression.steps:
                        if operator == ADD:
                            acc += cells[cell]
                        elif operator == SUB:
                            acc -= cells[cell]
                        elif operator == AND:
                            acc &= cells[cell]
                        elif operator == OR:
                            acc |= cells[cell]
                        elif operator == XOR:
                            acc ^= cells[cell]
                        elif operator == SHL:
                            acc = _shift_left(_wrap(acc), cells[cell])
                        else:  # SHR
                            count = cells[cell]
                            acc = _wrap(acc)
                            acc = acc >> count if 0 <= count < 16 else _shift_right(acc, count)
                    cells[expression.target] = ((acc + 0x8000) & 0xFFFF) - 0x8000
                    pc = b
                elif op == INC:
                    cells[a] = ((cells[a] + 1 + 0x8000) & 0xFFFF) - 0x8000
                elif op == DEC:
                    cells[a] = ((cells[a] - 1 + 0x8000) & 0xFFFF) - 0x8000
                elif op == JUMP_POSITIVE:
                    if cells[a] > 0:
                        # A jump taken: count the straight run it ends, check the budget,
                        # take a pending event, bound the next run by the step's limit.
                        # The other jumps do the same.
                        executed += pc - start
                        start = pc
                        if executed > budget:
                            break
                        pc = start = b if hardware.pending is None else divert(take(), b)
                        if executed + reach[pc] > check:
                            check = self._bound(pc, executed, stop_at)
                elif op == JUMP_ZERO:
                    if cells[a] == 0:
                        executed += pc - start
                        start = pc
                        if executed > budget:
                            break
                        pc = start = b if hardware.pending is None else divert(take(), b)
                        if executed + reach[pc] > check:
                            check = self._bound(pc, executed, stop_at)
                elif op == JUMP_NEGATIVE:
                    if cells[a] < 0:
                        executed += pc - start
                        start = pc
                        if executed > budget:
                            break
                        pc = start = b if hardware.pending is None else divert(take(), b)
                        if executed + reach[pc] > check:
                            check = self._bound(pc, executed, stop_at)
                elif op == JUMP:
                    executed += pc - start
                    start = pc
                    if executed > budget:
                        break
                    pc = start = b if hardware.pending is None else divert(take(), b)
                    if executed + reach[pc] > check:
                        check = self._bound(pc, executed, stop_at)
                elif op == CALL:
                    site = sites[a]
                    if executed + pc - start > budget:
                        executed += pc - start
                        break
                    call_counts.append(executed + pc - start)
                    self.pc = pc  # for current_line, while the device works
                    args = self._arguments(site, cells)
                    if site.waits:
                        started = hardware.start(site.form, args)
                        if started.status is not Status.OK:
                            raise DeviceError(refusal(started))
                        if not self._finish(site, hardware.poll()):
                            self.state, self.waiting = State.WAITING, site
                            self.acc, self.pc, self.executed = acc, pc, executed + pc - start
                            return State.WAITING
                    else:
                        answer = hardware.call(site.form, args)
                        if answer.status is Status.BUSY:  # only a poll may
                            raise DeviceError(refusal(answer))
                        self._finish(site, answer)
                    event = take()
                    if event is not None:
                        executed += pc - start
                        start = pc
                        pc = start = divert(event, pc)
                        check = self._bound(pc, executed, stop_at)
                elif op == LOAD:
                    acc = cells[a]
                elif op == COMPUTE:
                    first, operator, cell = computes[a]
                    acc = _operate(operator, cells[first], cells[cell])
                elif op == STORE:
                    cells[a] = ((acc + 0x8000) & 0xFFFF) - 0x8000
                elif op == ADD:
                    acc += cells[a]
                elif op == SUB:
                    acc -= cells[a]
                elif op == AND:
                    acc &= cells[a]
                elif op == OR:
                    acc |= cells[a]
                elif op == XOR:
                    acc ^= cells[a]
                elif op == SHL:
                    acc = _shift_left(_wrap(acc), cells[a])
                elif op == SHR:
                    count = cells[a]
                    acc = _wrap(acc)
                    acc = acc >> count if 0 <= count < 16 else _shift_right(acc, count)
                elif op == HALT:  # the step's limit: stop before this instruction
                    pc -= 1
                    self.acc, self.pc, self.executed = acc, pc, executed + pc - start
                    return State.RUNNING
                elif op == MOVE:
                    cells[a] = cells[b]
                elif op == DEC_JUMP_POSITIVE:
                    cells[a] = ((cells[a] - 1 + 0x8000) & 0xFFFF) - 0x8000
                    if cells[a] > 0:
                        executed += pc - start
                        start = pc
                        if executed > budget:
                            break
                        pc = start = b if hardware.pending is None else divert(take(), b)
                        if executed + reach[pc] > check:
                            check = self._bound(pc, executed, stop_at)
                elif STORE_JUMP_ZERO <= op <= STORE_JUMP_NEGATIVE:
                    value = cells[a] = ((acc + 0x8000) & 0xFFFF) - 0x8000
                    if (value == 0 if op == STORE_JUMP_ZERO
                            else value > 0 if op == STORE_JUMP_POSITIVE else value < 0):
                        executed += pc - start
                        start = pc
                        if executed > budget:
                            break
                        pc = start = b if hardware.pending is None else divert(take(), b)
                        if executed + reach[pc] > check:
                            check = self._bound(pc, executed, stop_at)
                else:  # END
                    pc = min(pc, last)  # running off the end is no instruction
                    self.acc, self.pc, self.executed = acc, pc, executed + pc - start
                    self.state = State.ENDED
                    ended = hardware.end()
                    if ended.status is not Status.OK:
                        return self._faulted(_Faulted(FaultKind.DEVICE, refusal(ended)), pc - 1,
                                             ended=True)
                    self.result = RunResult(tuple(cells[:R_CELL]))
                    return State.ENDED
        except (_Faulted, DeviceError) as error:
            # pc has already moved past the instruction that faulted.
            self.acc, self.pc, self.executed = acc, pc, executed + pc - start
            fault = (error if isinstance(error, _Faulted)
                     else _Faulted(FaultKind.DEVICE, str(error)))
            return self._faulted(fault, pc - 1)
        finally:
            self._unbound()
        self.acc, self.pc, self.executed = acc, pc, executed
        watchdog = _Faulted(FaultKind.BUDGET, budget_message(budget))
        return self._faulted(watchdog, pc - 1)

    # The step's limit: a HALT put in the code where the step must stop

    def _bound(self, pc: int, executed: int, stop_at: int) -> int:
        """Bound the straight run starting at `pc`, with `executed` instructions run, by
        the step's limit `stop_at`: if the run could pass it, put a HALT where the limit
        falls. What the next run start compares with: `stop_at`, or -1 while a HALT is
        in place (so that the next run start moves it)."""
        self._unbound()
        left = stop_at - executed
        if self.reach[pc] <= left:
            return stop_at
        halt = pc + left
        fused = self.fused_at[halt]
        if fused >= 0:  # the halt falls inside an EXPRESSION: run its instructions singly
            self._saved.append((fused, self.code[fused]))
            self.code[fused] = self.plain[fused]
        self._saved.append((halt, self.code[halt]))
        self.code[halt] = (HALT, 0, 0)
        return -1

    def _unbound(self) -> None:
        while self._saved:
            index, instruction = self._saved.pop()
            self.code[index] = instruction

    # The slow paths: calls, events and faults

    def _arguments(self, site: _CallSite, cells: list[int]) -> tuple[int, ...]:
        """The call's argument values, left to right; a variable's value outside its
        parameter's range is a fault."""
        values = []
        for param, arg in zip(site.params, site.args, strict=True):
            value = cells[arg.value] if arg.is_var else arg.value
            if arg.is_var and not param.low <= value <= param.high:
                raise _Faulted(FaultKind.ARGUMENT_RANGE, argument_range_message(
                    param.name, form_name(site.form), value, arg.value, param.low,
                    param.high))
            values.append(value)
        return tuple(values)

    def _finish(self, site: _CallSite, answer: Answer) -> bool:
        """Take a call's answer: False while BUSY; done, write what it read (checked
        first): the reserved variables, then R."""
        if answer.status is Status.BUSY:
            return False
        if answer.status is not Status.OK:
            raise DeviceError(answer.message)
        outcome = checked(site.form, answer.outcome)
        cells = self.cells
        for cell, value in zip(site.writes, outcome.writes, strict=True):
            cells[cell] = value
        if site.returns_value:
            assert outcome.result is not None
            cells[R_CELL] = outcome.result
        return True

    def _divert(self, event: LineLost | None, resume: int) -> int:
        """Where a lost-line event sends the program: its handler's index, or `resume`
        when there is no event or its mode calls for no jump."""
        if event is None:
            return resume
        label = lost_line_handler(event.mode, event.command)
        if label is None:
            return resume
        handler = self.handlers.get(label)
        if handler is None:
            raise _Faulted(FaultKind.MISSING_HANDLER,
                           missing_handler_message(event.mode, event.command, label))
        return handler

    def _faulted(self, fault: _Faulted, index: int | None, ended: bool = False) -> State:
        """Stop the vehicle, describe the fault at instruction `index` (None: before
        the first), and tell the device the program is over unless `ended` did."""
        message = fault.message
        stopped = self.hardware.stop()
        if stopped.status is not Status.OK:
            message += STOP_FAILED + refusal(stopped)
        if not ended:
            self.hardware.end()  # the fault is reported whatever the end answers
        self.state = State.FAULTED
        line = None if index is None else self._line_of(index)
        self.result = RunResult(tuple(self.cells[:R_CELL]), Fault(fault.kind, message, line))
        return State.FAULTED

    def current_line(self) -> int | None:
        """The source line of the call under way, or of the instruction run last between
        steps; None before the first instruction, or without a line map."""
        return self._line_of(self.pc - 1) if self.pc > 0 else None

    def _line_of(self, index: int) -> int | None:
        debug = self.program.image.debug
        instructions = self.program.instructions
        if debug is None or not instructions:
            return None
        offset = instructions[min(index, len(instructions) - 1)].offset
        return debug.line_at(offset)


def run(program: VerifiedProgram, device: Device, budget: int = DEFAULT_BUDGET) -> RunResult:
    """Run a verified program on a blocking `device`."""
    return Machine(program, Blocking(device), budget).run()
