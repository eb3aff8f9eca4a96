"""The reference VM: what every instruction of a verified .ilc program means.

Later implementations (a C VM on the vehicle) must behave exactly as this one does.
State: 53 variables (builtins.VARIABLES order, all 0 at start), the accumulator, the
result register R (the value of the last value-returning call, 0 at start) and the
program counter. Every value is a 16-bit two's complement integer and every result
wraps; shift counts are signed (see `_shift_left`).

Execution: the instruction at the program counter runs; running off the end of the code
is (END). A lost-line event (device.py) is taken between instructions: right after each
call instruction and after each jump taken. Its handler is the label Table 4 names for
the event's tracing mode and command: 2 MOV :98, 2 MVI :99, 3 MOV :96, 3 MVI :97.

Faults end the run after the device is stopped: a variable argument outside its range,
a lost line whose handler the program lacks, the watchdog's instruction budget used up,
and a device error (faults.py has their exit statuses).

The dispatch loop runs on instructions decoded once into (op, a, b) tuples, where jump
targets are instruction indices. Operands live in one list of cells: the variables at
0..52, R at 53, then the program's immediates; so LDV/LDI/LDR are one load and each ALU
operator is one case whatever its operand kind.
"""

from __future__ import annotations

from dataclasses import dataclass

from rl1.compiler.builtins import VARIABLES, Param

from . import isa
from .device import Device, DeviceError, form_name, perform
from .faults import DEFAULT_BUDGET, Fault, FaultKind, RunResult
from .verifier import VerifiedProgram

R_CELL = len(VARIABLES)
_INDEX = {name: index for index, name in enumerate(VARIABLES)}

# Table 4: the handler label by (tracing mode, command in effect).
HANDLERS = {(2, "MOV"): 98, (2, "MVI"): 99, (3, "MOV"): 96, (3, "MVI"): 97}

# The operations of the dispatch loop (not opcodes: decoding folds operand kinds).
(LOAD, STORE, ADD, SUB, AND, OR, XOR, SHL, SHR, INC, DEC,
 JUMP, JUMP_ZERO, JUMP_POSITIVE, JUMP_NEGATIVE, CALL, END) = range(17)

_ALU = (ADD, SUB, AND, OR, XOR, SHL, SHR)  # in isa.ALU_OPERATORS order
_SIMPLE = {"STV": STORE, "INC": INC, "DEC": DEC}
_JUMPS = {"JMP": JUMP, "JZ": JUMP_ZERO, "JGT": JUMP_POSITIVE, "JLT": JUMP_NEGATIVE}


@dataclass(frozen=True, slots=True)
class _CallSite:
    """A call instruction, decoded: its form, its arguments (cell index or constant),
    and the cells its results go to."""

    form: tuple[str, str | None]
    params: tuple[Param, ...]
    args: tuple[isa.Arg, ...]
    writes: tuple[int, ...]
    returns_value: bool


class _Faulted(Exception):
    def __init__(self, kind: FaultKind, message: str) -> None:
        self.kind = kind
        self.message = message


def _shift_left(value: int, count: int) -> int:
    """value << count on 16 bits; a count >= 16 gives 0, a negative one shifts right
    by -count (so -32768 shifts right by 32768)."""
    if count < 0:
        return _shift_right(value, -count)
    if count >= 16:
        return 0
    return (((value << count) + 0x8000) & 0xFFFF) - 0x8000


def _shift_right(value: int, count: int) -> int:
    """Arithmetic value >> count; a count >= 16 gives the sign (0 or -1), a negative
    one shifts left by -count."""
    if count < 0:
        return _shift_left(value, -count)
    if count >= 16:
        return -1 if value < 0 else 0
    return value >> count


class Machine:
    def __init__(self, program: VerifiedProgram, device: Device,
                 budget: int = DEFAULT_BUDGET) -> None:
        self.program = program
        self.device = device
        self.budget = budget
        self.cells: list[int] = [0] * (R_CELL + 1)
        self.sites: list[_CallSite] = []
        self.code = [self._decode(instruction) for instruction in program.instructions]
        self.code.append((END, 0, 0))  # running off the end is (END)
        index_of = program.index_of
        self.handlers = {label: index_of[offset]
                         for label, offset in program.image.handlers.items()}

    def _cell_of_immediate(self, value: int) -> int:
        if value not in self.cells[R_CELL + 1:]:
            self.cells.append(value)
        return self.cells.index(value, R_CELL + 1)

    def _decode(self, instruction: isa.Instruction) -> tuple[int, int, int]:
        info = instruction.info
        name, operands = info.name, instruction.operands
        if name == "END":
            return (END, 0, 0)
        if name == "LDV":
            return (LOAD, operands[0], 0)
        if name == "LDI":
            return (LOAD, self._cell_of_immediate(operands[0]), 0)
        if name == "LDR":
            return (LOAD, R_CELL, 0)
        if name in _SIMPLE:
            return (_SIMPLE[name], operands[0], 0)
        if name in _JUMPS:
            *condition, target = operands
            return (_JUMPS[name], condition[0] if condition else 0,
                    self.program.index_of[target])
        if isa.ALU_VAR <= info.opcode < isa.CALL_BASE:
            base = info.opcode & ~7
            op = _ALU[info.opcode - base]
            if base == isa.ALU_VAR:
                return (op, operands[0], 0)
            if base == isa.ALU_IMM:
                return (op, self._cell_of_immediate(operands[0]), 0)
            return (op, R_CELL, 0)
        form = info.form
        assert info.builtin is not None and form is not None
        self.sites.append(_CallSite(info.builtin, form.params, instruction.args,
                                    tuple(_INDEX[name] for name in form.writes),
                                    form.returns_value))
        return (CALL, len(self.sites) - 1, 0)

    # The dispatch loop

    def run(self) -> RunResult:
        """Run from the first instruction until (END) or a fault."""
        code = self.code
        cells = self.cells[:]
        acc = 0
        pc = 0
        try:
            for _ in range(self.budget):
                op, a, b = code[pc]
                pc += 1
                if op == LOAD:
                    acc = cells[a]
                elif op == STORE:
                    cells[a] = acc
                elif op == ADD:
                    acc = ((acc + cells[a] + 0x8000) & 0xFFFF) - 0x8000
                elif op == SUB:
                    acc = ((acc - cells[a] + 0x8000) & 0xFFFF) - 0x8000
                elif op == JUMP:
                    pc = self._after_jump(b)
                elif op == JUMP_ZERO:
                    if cells[a] == 0:
                        pc = self._after_jump(b)
                elif op == JUMP_POSITIVE:
                    if cells[a] > 0:
                        pc = self._after_jump(b)
                elif op == JUMP_NEGATIVE:
                    if cells[a] < 0:
                        pc = self._after_jump(b)
                elif op == INC:
                    cells[a] = ((cells[a] + 1 + 0x8000) & 0xFFFF) - 0x8000
                elif op == DEC:
                    cells[a] = ((cells[a] - 1 + 0x8000) & 0xFFFF) - 0x8000
                elif op == AND:
                    acc &= cells[a]  # & | ^ of two 16-bit signed values stay in range
                elif op == OR:
                    acc |= cells[a]
                elif op == XOR:
                    acc ^= cells[a]
                elif op == SHL:
                    acc = _shift_left(acc, cells[a])
                elif op == SHR:
                    acc = _shift_right(acc, cells[a])
                elif op == CALL:
                    handler = self._call(self.sites[a], cells)
                    if handler is not None:
                        pc = handler
                else:  # END
                    return RunResult(tuple(cells[:R_CELL]))
        except _Faulted as fault:
            # pc has already moved past the instruction that faulted.
            return RunResult(tuple(cells[:R_CELL]), self._fault(fault, pc - 1))
        budget = _Faulted(FaultKind.BUDGET, f"the program ran {self.budget} instructions "
                          "without ending (raise the budget if it should run longer)")
        return RunResult(tuple(cells[:R_CELL]), self._fault(budget, pc))

    # The slow paths: calls, events and faults

    def _after_jump(self, target: int) -> int:
        handler = self._take_event()
        return target if handler is None else handler

    def _call(self, site: _CallSite, cells: list[int]) -> int | None:
        """Carry out a call; the handler's index if a lost line interrupts, else None."""
        values = []
        for param, arg in zip(site.params, site.args, strict=True):
            value = cells[arg.value] if arg.is_var else arg.value
            if arg.is_var and not param.low <= value <= param.high:
                raise _Faulted(FaultKind.ARGUMENT_RANGE,
                               f"argument {param.name} of ({form_name(site.form)}) is "
                               f"{value} (the value of {VARIABLES[arg.value]}), outside "
                               f"{param.low}..{param.high}")
            values.append(value)
        try:
            outcome = perform(self.device, site.form, tuple(values))
        except DeviceError as error:
            raise _Faulted(FaultKind.DEVICE, str(error)) from None
        for cell, value in zip(site.writes, outcome.writes, strict=True):
            cells[cell] = value
        if site.returns_value:
            assert outcome.result is not None
            cells[R_CELL] = outcome.result
        return self._take_event()

    def _take_event(self) -> int | None:
        """The handler's index for a pending lost-line event, None if there is none."""
        try:
            event = self.device.poll_event()
        except DeviceError as error:
            raise _Faulted(FaultKind.DEVICE, str(error)) from None
        if event is None:
            return None
        label = HANDLERS.get((event.mode, event.command))
        if label is None:
            return None
        handler = self.handlers.get(label)
        if handler is None:
            raise _Faulted(FaultKind.MISSING_HANDLER,
                           f"the line was lost during {event.command} in tracing mode "
                           f"{event.mode}, which jumps to :{label}, but the program has "
                           f"no label :{label}")
        return handler

    def _fault(self, fault: _Faulted, index: int) -> Fault:
        """Stop the vehicle, then describe the fault at instruction `index`."""
        message = fault.message
        try:
            self.device.stop()
        except DeviceError as error:
            message += f"; stopping the vehicle failed too: {error}"
        return Fault(fault.kind, message, self._line_of(index))

    def _line_of(self, index: int) -> int | None:
        debug = self.program.image.debug
        instructions = self.program.instructions
        if debug is None or not instructions:
            return None
        offset = instructions[min(index, len(instructions) - 1)].offset
        return debug.line_at(offset)


def run(program: VerifiedProgram, device: Device, budget: int = DEFAULT_BUDGET) -> RunResult:
    """Run a verified program on `device`."""
    return Machine(program, device, budget).run()
