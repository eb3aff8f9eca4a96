"""A tree-walking interpreter over the checked AST, written from the language semantics.

It shares nothing with the code generator or the VM but the Device interface and the
fault kinds, so running both side by side on one program tests each against the other.
The program counter is an index into the program's statements in source order; a label
stands for the index of the first statement after it.

Lost-line events are taken right after each device call and each jump taken (the points
where the VM takes them too): an event in the middle of an expression abandons the rest
of its statement, as the VM abandons the rest of the statement's instructions.
"""

from __future__ import annotations

from dataclasses import dataclass

from rl1.vm.device import Device, DeviceError, form_name, perform
from rl1.vm.faults import (
    DEFAULT_BUDGET,
    Fault,
    FaultKind,
    RunResult,
    budget_message,
    missing_handler_message,
)
from rl1.vm.language import BUILTINS, VARIABLE_INDEX, VARIABLES, Form, lost_line_handler

from .frontend import ast


class NotRunnable(Exception):
    """The program has an error the checker reports; the interpreter cannot run it."""

    def __init__(self, line: int, message: str) -> None:
        super().__init__(f"line {line}: {message}")
        self.line = line


def interpret(program: ast.Program, device: Device, budget: int = DEFAULT_BUDGET) -> RunResult:
    """Run `program` on `device` until it ends or faults."""
    return Interpreter(program, device, budget).run()


# The arithmetic of the spec: 16-bit two's complement, wrapping, shifts by signed counts.
# Written apart from the VM's (vm/machine.py) on purpose: the differential tests hold
# each to the other, which a shared function would make a comparison with itself.


def wrap(value: int) -> int:
    return ((value + 0x8000) & 0xFFFF) - 0x8000


def shift_left(value: int, count: int) -> int:
    if count < 0:
        return shift_right(value, -count)
    return 0 if count >= 16 else wrap(value << count)


def shift_right(value: int, count: int) -> int:
    if count < 0:
        return shift_left(value, -count)
    if count >= 16:
        return -1 if value < 0 else 0
    return value >> count


def apply(op: ast.BinaryOperator, left: int, right: int) -> int:
    if op == "+":
        return wrap(left + right)
    if op == "-":
        return wrap(left - right)
    if op == "&":
        return wrap(left & right)
    if op == "|":
        return wrap(left | right)
    if op == "^":
        return wrap(left ^ right)
    if op == "<":
        return shift_left(left, right)
    return shift_right(left, right)


def holds(relation: ast.Relation, value: int) -> bool:
    if relation == "=":
        return value == 0
    return value > 0 if relation == ">" else value < 0


def constant(const: ast.Const) -> int:
    return wrap(const.value) if const.hex else const.value


# Control transfers out of the middle of a statement.


class _Jump(Exception):
    def __init__(self, target: int) -> None:
        self.target = target


class _Halt(Exception):
    pass


class _Faulted(Exception):
    def __init__(self, kind: FaultKind, message: str) -> None:
        self.kind = kind
        self.message = message


@dataclass(frozen=True, slots=True)
class _Resolved:
    """A call's form, looked up once."""

    form: tuple[str, str | None]
    spec: Form
    args: tuple[ast.Var | ast.Const, ...]


class Interpreter:
    def __init__(self, program: ast.Program, device: Device, budget: int = DEFAULT_BUDGET):
        self.device = device
        self.budget = budget
        self.steps = 0  # statements run so far
        self.line: int | None = None  # the source line of the statement running
        self.variables = [0] * len(VARIABLES)
        self.statements: list[ast.Statement] = []
        self.labels: dict[int, int] = {}
        self.calls: dict[ast.Call, _Resolved] = {}
        self._load(program)

    # Loading: the facts the interpreter relies on, which a checked program guarantees.

    def _load(self, program: ast.Program) -> None:
        for line in program.lines:
            if not line.ok:
                raise NotRunnable(line.number, "the line has a syntax error")
            if line.label is not None:
                number = line.label.number
                if number is None:
                    raise NotRunnable(line.number, f"`{line.label.text}` is not a label")
                if number in self.labels:
                    raise NotRunnable(line.number, f"label :{number:02d} is defined twice")
                self.labels[number] = len(self.statements)
            self.statements.extend(line.statements)
        for node in ast.walk(program):
            if isinstance(node, ast.Goto | ast.CondJump):
                self._label_index(node.target)
            elif isinstance(node, ast.Call):
                self.calls[node] = self._resolve(node)
            elif isinstance(node, ast.Assign):
                for operand in (node.first, *(step.operand for step in node.rest)):
                    if (isinstance(operand, ast.Call)
                            and not self._resolve(operand).spec.returns_value):
                        raise NotRunnable(operand.span.line, f"({operand.mnemonic.upper()}) "
                                          "returns no value to use in an expression")
            elif isinstance(node, ast.Const) and not node.hex and not (
                    -32768 <= node.value <= 32767):
                raise NotRunnable(node.span.line, f"{node.text} does not fit in 16 bits")

    def _label_index(self, target: ast.LabelRef) -> int:
        if target.number is None or target.number not in self.labels:
            raise NotRunnable(target.span.line, f"jump to `{target.text}`, which is not defined")
        return self.labels[target.number]

    def _resolve(self, call: ast.Call) -> _Resolved:
        builtin = BUILTINS.get(call.mnemonic.upper())
        if builtin is None:
            raise NotRunnable(call.span.line, f"`{call.mnemonic}` is not a built-in function")
        selector = None
        rest = call.args
        if builtin.has_selector and rest and isinstance(rest[0], ast.Selector):
            selector, rest = rest[0].letter.upper(), rest[1:]
        spec = builtin.form(selector)
        args = tuple(arg for arg in rest if not isinstance(arg, ast.Selector))
        if spec is None or len(args) != len(rest) or len(args) != len(spec.params):
            raise NotRunnable(call.span.line, f"({call.mnemonic} ...) has the wrong arguments")
        return _Resolved((builtin.mnemonic, selector), spec, args)

    # Running

    def run(self) -> RunResult:
        pc = 0
        statement: ast.Statement | None = None
        try:
            while pc < len(self.statements):
                statement = self.statements[pc]
                self.line = statement.span.line
                self.steps += 1
                try:
                    pc = self._execute(statement, pc + 1)
                except _Jump as jump:
                    pc = jump.target
        except _Halt:
            pass
        except _Faulted as fault:
            line = statement.span.line if statement is not None else None
            return RunResult(tuple(self.variables), self._fault(fault, line))
        return RunResult(tuple(self.variables))

    def _fault(self, fault: _Faulted, line: int | None) -> Fault:
        message = fault.message
        self.device.line = line  # what the device records of the stop says where it was
        try:
            self.device.stop()
        except DeviceError as error:
            message += f"; stopping the vehicle failed too: {error}"
        return Fault(fault.kind, message, line)

    def _execute(self, statement: ast.Statement, next_pc: int) -> int:
        """Run one statement; the index of the statement to run next."""
        # isinstance, not match: class patterns made this loop 14% slower (CPython 3.11).
        if isinstance(statement, ast.Assign):
            value = self._operand(statement.first)
            for step in statement.rest:
                value = apply(step.op, value, self._operand(step.operand))
            self.variables[VARIABLE_INDEX[statement.target.name]] = value
        elif isinstance(statement, ast.IncDec):
            index = VARIABLE_INDEX[statement.target.name]
            delta = 1 if statement.step == "++" else -1
            self.variables[index] = wrap(self.variables[index] + delta)
        elif isinstance(statement, ast.Goto):
            return self._jump(statement.target)
        elif isinstance(statement, ast.CondJump):
            value = self.variables[VARIABLE_INDEX[statement.var.name]]
            if holds(statement.relation, value):
                return self._jump(statement.target)
        else:
            self._call(statement.call)
        return next_pc

    def _jump(self, target: ast.LabelRef) -> int:
        self._watchdog()
        self._take_event()
        return self._label_index(target)

    def _watchdog(self) -> None:
        """At each jump taken and before each device call, as the VM does: every loop
        takes a jump, so a runaway program always meets it."""
        if self.steps > self.budget:
            raise _Faulted(FaultKind.BUDGET, budget_message(self.budget, "statements"))

    def _operand(self, operand: ast.Operand) -> int:
        if isinstance(operand, ast.Var):
            return self.variables[VARIABLE_INDEX[operand.name]]
        if isinstance(operand, ast.Const):
            return constant(operand)
        result = self._call(operand)
        assert result is not None  # _load refused result-less calls as operands
        return result

    def _call(self, call: ast.Call) -> int | None:
        resolved = self.calls[call]
        if resolved.form == ("END", None):
            raise _Halt
        self._watchdog()
        values = tuple(self._operand(arg) for arg in resolved.args)
        for param, arg, value in zip(resolved.spec.params, resolved.args, values, strict=True):
            if not param.low <= value <= param.high:
                source = f" (the value of {arg.name})" if isinstance(arg, ast.Var) else ""
                raise _Faulted(FaultKind.ARGUMENT_RANGE,
                               f"argument {param.name} of ({form_name(resolved.form)}) is "
                               f"{value}{source}, outside {param.low}..{param.high}")
        try:
            outcome = perform(self.device, resolved.form, values, self.line)
        except DeviceError as error:
            raise _Faulted(FaultKind.DEVICE, str(error)) from None
        for name, value in zip(resolved.spec.writes, outcome.writes, strict=True):
            self.variables[VARIABLE_INDEX[name]] = value
        self._take_event()
        return outcome.result

    def _take_event(self) -> None:
        """Jump to the handler of a pending lost-line event, if there is one."""
        try:
            event = self.device.poll_event()
        except DeviceError as error:
            raise _Faulted(FaultKind.DEVICE, str(error)) from None
        if event is None:
            return
        label = lost_line_handler(event.mode, event.command)
        if label is None:
            return
        if label not in self.labels:
            raise _Faulted(FaultKind.MISSING_HANDLER,
                           missing_handler_message(event.mode, event.command, label))
        raise _Jump(self.labels[label])
