"""Lowering: the checked AST to IR, statement by statement, without optimizing (-O0).

`V=a op b` becomes load a; op b; store V. A call operand is emitted where it stands and
its result read from R, so side effects keep the source's left-to-right order: in
`A=x+(IMG)` the load of x comes before IMG overwrites x. A label starts a block, a jump
or `(END)` ends one, a conditional jump ends one with a branch to the label or to the
statement after it, and falling off the end of the program ends it.
"""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.compiler.frontend.collector import collector_paused
from rl1.compiler.frontend.parser import parse_line
from rl1.compiler.frontend.source import iter_lines
from rl1.vm.language import HANDLER_LABELS

from . import ir


class LoweringError(Exception):
    """The AST holds a problem the checker refuses (an undefined label, a bad call...);
    lowering runs only on programs without errors, so this is a compiler bug."""


def lower(program: ast.Program) -> ir.Program:
    """The IR of a program the checker accepted."""
    lowering = Lowering()
    for line in program.lines:
        lowering.take(line)
    return lowering.program()


def lower_text(text: str) -> ir.Program:
    """The IR of a program the checker accepted, from its text: each line parsed and
    lowered in turn, so that no tree is held."""
    lowering = Lowering()
    with collector_paused():
        for index, line_text in enumerate(iter_lines(text)):
            lowering.take(parse_line(line_text, index + 1)[0])
    return lowering.program()


class Lowering:
    """The IR of a program made as its lines are handed over in order (`take`), so that
    the compile lowers each line as the check parses it (driver.py) and no tree is held.
    A line the lowering refuses stops it, since the program has an error the check
    reports; `program` raises the refusal if the check let the program through."""

    __slots__ = ("_lowerer", "_refused")

    def __init__(self) -> None:
        self._lowerer = _Lowerer()
        self._refused: LoweringError | None = None

    def take(self, line: ast.Line) -> None:
        if self._refused is None:
            try:
                self._lowerer.line(line)
            except LoweringError as refused:
                self._refused = refused

    @property
    def blocks(self) -> int:
        """How many blocks the lines taken have ended."""
        return len(self._lowerer.blocks)

    def program(self) -> ir.Program:
        """The IR of the lines taken, which the checker accepted."""
        if self._refused is not None:
            raise self._refused
        lowered = self._lowerer.program()
        problems = ir.validate(lowered)
        if problems:
            raise LoweringError("the checker let through a program with errors: "
                                + "; ".join(problems))
        return lowered


class _Lowerer:
    def __init__(self) -> None:
        self.blocks: dict[ir.BlockId, ir.Block] = {}
        self.handlers: dict[int, ir.BlockId] = {}
        self.block_id: ir.BlockId | None = None  # the open block, None after a jump or end
        self.code: list[ir.Instruction] = []
        self.unlabelled = 0
        self.last_line = 1
        # One object for each variable and constant (they are frozen): a long program's
        # IR was otherwise half operands (80 of the 192 bytes of `A=1`).
        self.variables: dict[str, ir.Var] = {}
        self.constants: dict[int, ir.Imm] = {}

    def line(self, line: ast.Line) -> None:
        if line.label is not None:
            self.start_label(line.label)
        for statement in line.statements:
            self.statement(statement, line.number)
        self.last_line = line.number

    def program(self) -> ir.Program:
        if self.block_id is not None or not self.blocks:
            self.finish(ir.End(self.last_line))
        return ir.Program(self.blocks, next(iter(self.blocks)), self.handlers)

    # Blocks -------------------------------------------------------------------------

    def open_block(self, named: ir.BlockId | None = None) -> None:
        """Open an unlabelled block unless one is open: at the start of the program,
        for the fall-through of a conditional jump (`named` as its branch names it, one
        string for both), or for code after a jump or `(END)` (which only a label could
        reach, so nothing does)."""
        if self.block_id is None:
            self.block_id = named or f"B{self.unlabelled}"
            self.unlabelled += 1

    def finish(self, terminator: ir.Terminator) -> None:
        self.open_block()
        assert self.block_id is not None
        if self.code:
            self.blocks[self.block_id] = ir.Block(self.block_id, self.code, terminator)
            self.code = []
        else:  # the list stays open for the next block's code
            self.blocks[self.block_id] = ir.Block(self.block_id, ir.NO_INSTRUCTIONS,
                                                  terminator)
        self.block_id = None

    def start_label(self, label: ast.LabelDef) -> None:
        block_id = self.target(label.number, label.text, label.span.line)
        if block_id in self.blocks or block_id == self.block_id:
            raise LoweringError(f"line {label.span.line}: `{label.text}` is defined twice")
        if self.block_id is not None:
            self.finish(ir.Jump(block_id, label.span.line))
        self.block_id = block_id
        if label.number is not None and label.number in HANDLER_LABELS:
            self.handlers[label.number] = block_id

    @staticmethod
    def target(number: int | None, text: str, line: int) -> ir.BlockId:
        if number is None:
            raise LoweringError(f"line {line}: `{text}` is not a two-digit label")
        return ir.label_block(number)

    # Statements ---------------------------------------------------------------------

    def emit(self, instruction: ir.Instruction) -> None:
        self.open_block()
        self.code.append(instruction)

    def statement(self, statement: ast.Statement, line: int) -> None:
        # isinstance, not match: class patterns made lowering 8% slower (CPython 3.11).
        if isinstance(statement, ast.Assign):
            self.operand(statement.first, None, line)
            for step in statement.rest:
                self.operand(step.operand, step.op, line)
            self.emit(ir.Store(self.variable(statement.target), line))
        elif isinstance(statement, ast.IncDec):
            self.emit(ir.StepVar(self.variable(statement.target), statement.step, line))
        elif isinstance(statement, ast.Goto):
            ref = statement.target
            self.finish(ir.Jump(self.target(ref.number, ref.text, line), line))
        elif isinstance(statement, ast.CondJump):
            ref = statement.target
            taken = self.target(ref.number, ref.text, line)
            self.open_block()
            fall_through = f"B{self.unlabelled}"
            self.finish(ir.Branch(self.variable(statement.var), statement.relation,
                                  taken, fall_through, line))
            self.open_block(fall_through)
        elif statement.call.is_end:
            if statement.call.args:
                raise LoweringError(f"line {line}: `(END)` takes no arguments")
            self.finish(ir.End(line))
        else:
            self.emit(self.call(statement.call, line))

    def operand(self, operand: ast.Operand, op: ast.BinaryOperator | None, line: int) -> None:
        """Load the first operand of an expression (op None) or apply the next one."""
        source: ir.Operand
        if isinstance(operand, ast.Call):
            self.emit(self.call(operand, line))
            source = ir.R
        else:
            source = self.argument(operand)
        self.emit(ir.Load(source, line) if op is None else ir.Operate(op, source, line))

    def call(self, call: ast.Call, line: int) -> ir.Call:
        selector, args = None, call.args
        if args and isinstance(args[0], ast.Selector):
            selector, args = args[0].letter.upper(), args[1:]
        lowered: list[ir.Argument] = []
        for arg in args:
            if isinstance(arg, ast.Selector):
                raise LoweringError(f"line {line}: a selector `{arg.letter}` out of place")
            lowered.append(self.argument(arg))
        return ir.Call(call.mnemonic.upper(), selector, tuple(lowered), line)

    def argument(self, arg: ast.Var | ast.Const) -> ir.Argument:
        if isinstance(arg, ast.Var):
            return self.variable(arg)
        constant = self.constants.get(arg.value)
        if constant is None:
            constant = self.constants[arg.value] = ir.Imm(arg.value)
        return constant

    def variable(self, var: ast.Var) -> ir.Var:
        shared = self.variables.get(var.name)
        if shared is None:
            shared = self.variables[var.name] = ir.Var(var.name)
        return shared
