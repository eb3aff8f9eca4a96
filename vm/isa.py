"""The .ilc instruction set, in one table.

An accumulator machine: expressions load the accumulator, operate on it with a variable,
an immediate or the result register R, and store it. Built-in calls are instructions of
their own; those that return a value leave it in R. spec/ilc.md documents the same
table for people; this module is its executable form.

Encoding (little-endian, no alignment): one opcode byte, then the operands the table
lists for that opcode, so an instruction's length is known from its first byte.
- VAR: 1 byte, a variable index 0..52 (builtins.VARIABLES order).
- IMM: 2 bytes, a signed 16-bit immediate.
- BYTE: 1 byte, a signed 8-bit immediate (format 1.2's MOVB).
- ADDR: 2 bytes, an unsigned offset into the code section (an instruction boundary).
- ARGS: a call's arguments: 1 mask byte (bit i set: argument i is a variable), then
  2 bytes per argument, an IMM or a variable index. Calls with no argument have none.
  The compact calls of format 1.3 (opcode = the call's | COMPACT_CALL_BIT) take 1 byte
  per argument: a BYTE or a variable index.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import Enum

from .language import BUILTINS, Form


class Operand(Enum):
    VAR = "var"  # 1 byte
    IMM = "imm"  # 2 bytes, signed
    BYTE = "byte"  # 1 byte, signed
    ADDR = "addr"  # 2 bytes, unsigned
    ARGS = "args"  # mask byte + 2 bytes per argument; the arity comes from the opcode


@dataclass(frozen=True, slots=True)
class OpInfo:
    opcode: int
    name: str
    operands: tuple[Operand, ...]
    meaning: str
    builtin: tuple[str, str | None] | None = None  # (mnemonic, selector) for calls
    arity: int = 0  # number of call arguments
    minor: int = 0  # the format minor version that added it (a file using it says so)
    arg_size: int = 2  # bytes per call argument: 1 in the compact calls

    @property
    def compact(self) -> bool:
        """Whether it is a compact call (arguments of a byte each)."""
        return self.arg_size == 1

    @property
    def length(self) -> int:
        size = 1
        for operand in self.operands:
            if operand in (Operand.VAR, Operand.BYTE):
                size += 1
            elif operand is Operand.ARGS:
                size += 1 + self.arg_size * self.arity
            else:
                size += 2
        return size

    @property
    def form(self) -> Form | None:
        if self.builtin is None:
            return None
        mnemonic, selector = self.builtin
        return BUILTINS[mnemonic].form(selector)


ALU_OPERATORS = ("+", "-", "&", "|", "^", "<", ">")
_ALU_NAMES = ("ADD", "SUB", "AND", "OR", "XOR", "SHL", "SHR")
_ALU_MEANINGS = ("acc + x", "acc - x", "acc & x", "acc | x", "acc ^ x",
                 "acc shifted left by x", "acc shifted right (arithmetic) by x")

# Bases of the three operand kinds of the ALU block; opcode = base + operator index.
ALU_VAR, ALU_IMM, ALU_RESULT = 0x10, 0x18, 0x20

JUMP_IF = {"=": 0x31, ">": 0x32, "<": 0x33}  # conditional jump opcode by relation

# The superinstructions of -O2 (spec/ilc.md, section 7) came with this minor version of
# the format; it is written here once, so that a merge with another 1.x can renumber it.
FUSED_MINOR = 2
STORE_JUMP_IF = {"=": 0x35, ">": 0x36, "<": 0x37}  # store acc, then jump on it
# The load-and-operate superinstructions (format 1.2): acc = first op second, in blocks of
# 8 by the kinds of the two operands, the operator in the low 3 bits as in the ALU block.
# An expression's load and first operation in one: `V=a-b` is COMPUTE then STV.
COMPUTE_VAR_VAR, COMPUTE_VAR_IMM, COMPUTE_RESULT_VAR, COMPUTE_RESULT_IMM = 0x60, 0x68, 0x70, 0x78

# The compact calls (-O2, format 1.3): a call whose constant arguments fit a byte, with a
# byte an argument; its opcode is the call's with this bit set, so that the C VM clears
# it to find the call (a call's descriptor, and the opcode its callbacks are given).
COMPACT_MINOR = 3
COMPACT_CALL_BIT = 0x80
COMPACT_SUFFIX = "S"  # MOVS 4, 4: MOV 4, 4 in 4 bytes instead of 6

# The built-in forms, in opcode order from CALL_BASE; END is opcode 0.
CALL_BASE = 0x40
CALL_FORMS: tuple[tuple[str, str | None], ...] = (
    ("FRE", None), ("HLD", None), ("ORG", None), ("MVI", None), ("MOV", None),
    ("STR", None), ("STL", None), ("STX", None), ("ROT", None), ("TRC", None),
    ("TIM", None), ("KYC", None), ("KYO", None), ("SCN", None), ("IMG", None),
    ("CAM", "Z"), ("CAM", "U"), ("CAM", "D"), ("CAM", "A"), ("CAM", "P"), ("CAM", "R"),
    ("ULT", "A"), ("ULT", "B"), ("ULT", "C"), ("ULT", "D"),
    ("LMP", None), ("INP", None), ("OUT", None), ("FZO", None), ("FZI", None),
)


# Each load-and-operate block: base, mnemonic suffix, operands, and the two operands as
# the meaning names them.
_COMPUTE_KINDS = (
    (COMPUTE_VAR_VAR, "VV", (Operand.VAR, Operand.VAR), "V[v]", "V[w]"),
    (COMPUTE_VAR_IMM, "VI", (Operand.VAR, Operand.IMM), "V[v]", "i"),
    (COMPUTE_RESULT_VAR, "RV", (Operand.VAR,), "R", "V[v]"),
    (COMPUTE_RESULT_IMM, "RI", (Operand.IMM,), "R", "i"),
)


def _table() -> dict[int, OpInfo]:
    rows = [
        OpInfo(0x00, "END", (), "end the program", ("END", None)),
        OpInfo(0x01, "LDV", (Operand.VAR,), "acc = V[v]"),
        OpInfo(0x02, "LDI", (Operand.IMM,), "acc = i"),
        OpInfo(0x03, "LDR", (), "acc = R (the last call's result)"),
        OpInfo(0x04, "STV", (Operand.VAR,), "V[v] = acc"),
        OpInfo(0x05, "INC", (Operand.VAR,), "V[v] = V[v] + 1"),
        OpInfo(0x06, "DEC", (Operand.VAR,), "V[v] = V[v] - 1"),
        OpInfo(0x30, "JMP", (Operand.ADDR,), "jump to a"),
        OpInfo(0x31, "JZ", (Operand.VAR, Operand.ADDR), "jump to a if V[v] = 0"),
        OpInfo(0x32, "JGT", (Operand.VAR, Operand.ADDR), "jump to a if V[v] > 0"),
        OpInfo(0x33, "JLT", (Operand.VAR, Operand.ADDR), "jump to a if V[v] < 0"),
        OpInfo(0x07, "MOVV", (Operand.VAR, Operand.VAR), "V[v] = V[w] (the second v)",
               minor=FUSED_MINOR),
        OpInfo(0x08, "MOVI", (Operand.VAR, Operand.IMM), "V[v] = i", minor=FUSED_MINOR),
        OpInfo(0x09, "MOVR", (Operand.VAR,), "V[v] = R (the last call's result)",
               minor=FUSED_MINOR),
        OpInfo(0x0A, "MOVB", (Operand.VAR, Operand.BYTE), "V[v] = b", minor=FUSED_MINOR),
        OpInfo(0x34, "DJGT", (Operand.VAR, Operand.ADDR),
               "V[v] = V[v] - 1, then jump to a if V[v] > 0", minor=FUSED_MINOR),
        OpInfo(0x35, "SJZ", (Operand.VAR, Operand.ADDR),
               "V[v] = acc, then jump to a if V[v] = 0", minor=FUSED_MINOR),
        OpInfo(0x36, "SJGT", (Operand.VAR, Operand.ADDR),
               "V[v] = acc, then jump to a if V[v] > 0", minor=FUSED_MINOR),
        OpInfo(0x37, "SJLT", (Operand.VAR, Operand.ADDR),
               "V[v] = acc, then jump to a if V[v] < 0", minor=FUSED_MINOR),
    ]
    for index, (name, meaning) in enumerate(zip(_ALU_NAMES, _ALU_MEANINGS, strict=True)):
        rows.append(OpInfo(ALU_VAR + index, name + "V", (Operand.VAR,),
                           meaning.replace("x", "V[v]") + ", into acc"))
        rows.append(OpInfo(ALU_IMM + index, name + "I", (Operand.IMM,),
                           meaning.replace("x", "i") + ", into acc"))
        rows.append(OpInfo(ALU_RESULT + index, name + "R", (),
                           meaning.replace("x", "R") + ", into acc"))
        for base, suffix, kinds, first, second in _COMPUTE_KINDS:
            rows.append(OpInfo(base + index, name + suffix, kinds,
                               "acc = " + meaning.replace("acc", first).replace("x", second),
                               minor=FUSED_MINOR))
    for index, (mnemonic, selector) in enumerate(CALL_FORMS):
        form = BUILTINS[mnemonic].form(selector)
        assert form is not None
        arity = len(form.params)
        name = mnemonic + (selector or "")
        rows.append(OpInfo(CALL_BASE + index, name, (Operand.ARGS,) if arity else (),
                           form.summary + (" R = result." if form.returns_value else ""),
                           (mnemonic, selector), arity))
        if arity:
            rows.append(OpInfo(COMPACT_CALL_BIT | (CALL_BASE + index), name + COMPACT_SUFFIX,
                               (Operand.ARGS,), form.summary
                               + (" R = result." if form.returns_value else "")
                               + " Arguments of a byte.",
                               (mnemonic, selector), arity, COMPACT_MINOR, arg_size=1))
    return {row.opcode: row for row in rows}


OPCODES: dict[int, OpInfo] = _table()
BY_NAME: dict[str, OpInfo] = {info.name: info for info in OPCODES.values()}
BY_FORM: dict[tuple[str, str | None], OpInfo] = {
    info.builtin: info for info in OPCODES.values()
    if info.builtin is not None and not info.compact
}


def code_minor(code: bytes) -> int:
    """The format minor version that code needs: the newest that added one of its
    instructions. It reads up to the first opcode it does not know, so that any bytes
    can be written (the verifier is what refuses them)."""
    minor = offset = 0
    while offset < len(code) and (info := OPCODES.get(code[offset])) is not None:
        minor = max(minor, info.minor)
        offset += info.length
    return minor


@dataclass(frozen=True, slots=True)
class Arg:
    """A call argument: an immediate, or (is_var) a variable index."""

    is_var: bool
    value: int


@dataclass(frozen=True, slots=True)
class Instruction:
    """One decoded instruction. `operands` holds the VAR, IMM and ADDR values in table
    order; `args` the call arguments."""

    offset: int
    info: OpInfo
    operands: tuple[int, ...] = ()
    args: tuple[Arg, ...] = ()

    @property
    def length(self) -> int:
        return self.info.length


class DecodeError(Exception):
    def __init__(self, offset: int, message: str) -> None:
        super().__init__(f"byte {offset}: {message}")
        self.offset = offset


# How a call argument is encoded, by (bytes an argument, whether it is a variable).
_ARG_FORMATS = {(2, True): "<H", (2, False): "<h", (1, True): "<B", (1, False): "<b"}


def decode_at(code: bytes, offset: int) -> Instruction:
    """Decode the instruction at `offset`; DecodeError for an unknown opcode or one cut
    off by the end of the code. Operand values are not range-checked here."""
    info = OPCODES.get(code[offset])
    if info is None:
        raise DecodeError(offset, f"unknown opcode 0x{code[offset]:02X}")
    if offset + info.length > len(code):
        raise DecodeError(offset, f"{info.name} needs {info.length} bytes, "
                                  f"only {len(code) - offset} remain in the code")
    position = offset + 1
    operands: list[int] = []
    args: list[Arg] = []
    for operand in info.operands:
        if operand is Operand.VAR:
            operands.append(code[position])
            position += 1
        elif operand is Operand.IMM:
            operands.append(struct.unpack_from("<h", code, position)[0])
            position += 2
        elif operand is Operand.BYTE:
            operands.append(struct.unpack_from("<b", code, position)[0])
            position += 1
        elif operand is Operand.ADDR:
            operands.append(struct.unpack_from("<H", code, position)[0])
            position += 2
        else:
            mask = code[position]
            position += 1
            for index in range(info.arity):
                is_var = bool(mask >> index & 1)
                fmt = _ARG_FORMATS[info.arg_size, is_var]
                args.append(Arg(is_var, struct.unpack_from(fmt, code, position)[0]))
                position += info.arg_size
    return Instruction(offset, info, tuple(operands), tuple(args))


def encode(info: OpInfo, operands: tuple[int, ...] = (), args: tuple[Arg, ...] = ()) -> bytes:
    """The bytes of one instruction (the inverse of decode_at)."""
    out = bytearray([info.opcode])
    values = iter(operands)
    for operand in info.operands:
        if operand is Operand.VAR:
            out.append(next(values))
        elif operand is Operand.IMM:
            out += struct.pack("<h", next(values))
        elif operand is Operand.BYTE:
            out += struct.pack("<b", next(values))
        elif operand is Operand.ADDR:
            out += struct.pack("<H", next(values))
        else:
            mask = sum(1 << index for index, arg in enumerate(args) if arg.is_var)
            out.append(mask)
            for arg in args:
                out += struct.pack(_ARG_FORMATS[info.arg_size, arg.is_var], arg.value)
    return bytes(out)
