"""Code generation: IR to an .ilc image (code, handler table, features, line map).

Blocks are laid out in the IR's order. Each IR instruction becomes one machine
instruction; a terminator becomes a jump unless its target is the block laid out next
(the IR never falls through, the machine code does). Sizes depend only on the layout,
so one pass places every block and a second encodes with the addresses resolved.
"""

from __future__ import annotations

from dataclasses import dataclass

from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.diagnostics import Diagnostic, Severity
from rl1.vm import ilc, isa
from rl1.vm.language import BUILTINS, VARIABLE_INDEX

from . import ir


class CodegenError(Exception):
    """The program does not fit a limit of the .ilc format; `diagnostic` says which."""

    def __init__(self, diagnostic: Diagnostic) -> None:
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic


@dataclass(frozen=True, slots=True)
class _MachineOp:
    """One instruction before addresses are known: a BlockId operand stands for the
    address of that block."""

    info: isa.OpInfo
    operands: tuple[int | ir.BlockId, ...]
    args: tuple[isa.Arg, ...]
    line: int


def generate(program: ir.Program, source_name: str, *, debug: bool = True) -> ilc.Image:
    """The image of a valid IR program, with its line map unless `debug` is False (the
    source's name in it as `ilc.debug_source_name` writes it);
    CodegenError when the code passes 65535 bytes or the map a line it cannot record."""
    layout = [(block.id, _select(block, following))
              for block, following in program.laid_out()]
    block_offsets: dict[ir.BlockId, int] = {}
    offset = 0
    for block_id, ops in layout:
        block_offsets[block_id] = offset
        for op in ops:
            if offset + op.info.length > ilc.MAX_CODE_SIZE:
                raise CodegenError(_too_large(op.line))
            if debug and op.line > ilc.MAX_LINE:
                raise CodegenError(line_too_far(op.line))
            offset += op.info.length
    code = bytearray()
    lines: list[tuple[int, int]] = []
    for _, ops in layout:
        for op in ops:
            lines.append((len(code), op.line))
            operands = tuple(block_offsets[value] if isinstance(value, str) else value
                             for value in op.operands)
            code += isa.encode(op.info, operands, op.args)
    features = {BUILTINS[instruction.mnemonic].feature
                for block in program for instruction in block.instructions
                if isinstance(instruction, ir.Call)}
    return ilc.Image(
        bytes(code),
        {label: block_offsets[block_id] for label, block_id in program.handlers.items()},
        frozenset(feature for feature in features if feature is not None),
        ilc.DebugInfo(ilc.debug_source_name(source_name), tuple(lines)) if debug else None,
    )


def _too_large(line: int) -> Diagnostic:
    return Diagnostic(
        "E0190", Severity.ERROR,
        f"the compiled code passes {ilc.MAX_CODE_SIZE} bytes at line {line}: .ilc code "
        "addresses are 16-bit, so a program's code must fit in 64 KiB",
        Span(line, 1, line, 1),
        help="split the program into smaller programs, or shorten repeated code "
             "with a loop",
    )


def line_too_far(line: int) -> Diagnostic:
    return Diagnostic(
        "E0191", Severity.ERROR,
        f"line {line} holds code, but the .ilc debug section records line numbers up to "
        f"{ilc.MAX_LINE} only",
        Span(line, 1, line, 1),
        help="compile with -s to leave the debug section out, or remove blank and "
             "comment lines before this one",
    )


def _select(block: ir.Block, following: ir.BlockId | None) -> list[_MachineOp]:
    """The machine instructions of one block, given the block laid out after it."""
    ops = [_instruction(instruction) for instruction in block.instructions]
    terminator = block.terminator
    if isinstance(terminator, ir.End):
        if terminator.written:
            ops.append(_MachineOp(isa.BY_NAME["END"], (), (), terminator.line))
        return ops
    if isinstance(terminator, ir.Jump):
        otherwise = terminator.target
    else:
        if isinstance(terminator, ir.Branch):
            opcode = isa.JUMP_IF[terminator.relation]
        elif isinstance(terminator, ir.StoreBranch):
            opcode = isa.STORE_JUMP_IF[terminator.relation]
        else:
            opcode = isa.BY_NAME["DJGT"].opcode
        ops.append(_MachineOp(isa.OPCODES[opcode],
                              (VARIABLE_INDEX[terminator.var.name], terminator.if_true),
                              (), terminator.line))
        otherwise = terminator.if_false
    if otherwise != following:
        ops.append(_MachineOp(isa.BY_NAME["JMP"], (otherwise,), (), terminator.line))
    return ops


_LOADS = ("LDV", "LDI", "LDR")  # by source kind, as _source numbers them
_ALU_BASES = (isa.ALU_VAR, isa.ALU_IMM, isa.ALU_RESULT)


def _instruction(instruction: ir.Instruction) -> _MachineOp:
    # isinstance, not match: class patterns made code generation 5% slower (CPython 3.11).
    line = instruction.line
    if isinstance(instruction, ir.Load):
        kind, operands = _source(instruction.source)
        return _MachineOp(isa.BY_NAME[_LOADS[kind]], operands, (), line)
    if isinstance(instruction, ir.Operate):
        kind, operands = _source(instruction.source)
        opcode = _ALU_BASES[kind] + isa.ALU_OPERATORS.index(instruction.op)
        return _MachineOp(isa.OPCODES[opcode], operands, (), line)
    if isinstance(instruction, ir.Store):
        return _MachineOp(isa.BY_NAME["STV"], (VARIABLE_INDEX[instruction.target.name],),
                          (), line)
    if isinstance(instruction, ir.StepVar):
        name = "INC" if instruction.step == "++" else "DEC"
        return _MachineOp(isa.BY_NAME[name], (VARIABLE_INDEX[instruction.target.name],),
                          (), line)
    if isinstance(instruction, ir.Move):
        kind, operands = _source(instruction.source)
        if isinstance(instruction.source, ir.Imm) and -0x80 <= instruction.source.value <= 0x7F:
            return _MachineOp(isa.BY_NAME["MOVB"], (VARIABLE_INDEX[instruction.target.name],
                                                     instruction.source.value), (), line)
        return _MachineOp(isa.BY_NAME[("MOVV", "MOVI", "MOVR")[kind]],
                          (VARIABLE_INDEX[instruction.target.name], *operands), (), line)
    if isinstance(instruction, ir.Compute):
        return _compute(instruction)
    args = tuple(isa.Arg(True, VARIABLE_INDEX[arg.name]) if isinstance(arg, ir.Var)
                 else isa.Arg(False, arg.value) for arg in instruction.args)
    call = isa.BY_FORM[instruction.mnemonic, instruction.selector]
    if instruction.compact:
        call = isa.OPCODES[call.opcode | isa.COMPACT_CALL_BIT]
    return _MachineOp(call, (), args, line)


def _compute(compute: ir.Compute) -> _MachineOp:
    """A load-and-operate: its block by the kinds of its two operands."""
    first = () if isinstance(compute.first, ir.Result) else (VARIABLE_INDEX[compute.first.name],)
    second_kind, second = _source(compute.second)
    base = {(False, 0): isa.COMPUTE_VAR_VAR, (False, 1): isa.COMPUTE_VAR_IMM,
            (True, 0): isa.COMPUTE_RESULT_VAR, (True, 1): isa.COMPUTE_RESULT_IMM}[
        isinstance(compute.first, ir.Result), second_kind]
    opcode = base + isa.ALU_OPERATORS.index(compute.op)
    return _MachineOp(isa.OPCODES[opcode], (*first, *second), (), compute.line)


def _source(source: ir.Operand) -> tuple[int, tuple[int, ...]]:
    """The kind of a source operand (0 variable, 1 immediate, 2 R) and its encoding."""
    if isinstance(source, ir.Var):
        return 0, (VARIABLE_INDEX[source.name],)
    if isinstance(source, ir.Imm):
        return 1, (source.value,)
    return 2, ()
