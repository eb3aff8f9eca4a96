"""The .ilc verifier: every check a file must pass before any of it runs.

After `verify` accepts a file, the VM needs no check of its own on the code: every opcode
is known, every instruction is whole, every jump and handler lands on an instruction,
every variable index names a variable and every constant argument is in its range.
What remains for run time is what only run time knows (a variable argument's value).

Errors carry FILE offsets (spec/ilc.md, "Verifier"), pointing at the offending byte:
the operand, not just its instruction; their messages also give the code offset.
"""

from __future__ import annotations

from dataclasses import dataclass

from . import isa
from .ilc import Container, IlcFormatError, Image, Refusal, read
from .language import BUILTINS, HANDLER_LABELS, VARIABLES


class VerifyError(IlcFormatError):
    """A file the verifier refuses; `offset` is a byte offset in the file."""


@dataclass(frozen=True)
class VerifiedProgram:
    """A verified image and its instructions, decoded once for the VM's dispatch loop."""

    image: Image
    instructions: tuple[isa.Instruction, ...]
    index_of: dict[int, int]  # code offset of an instruction -> its index in `instructions`


def verify(data: bytes) -> VerifiedProgram:
    """Check `data` in one pass over its bytes; VerifyError on the first problem."""
    try:
        container = read(data)
    except IlcFormatError as error:
        raise VerifyError(error.offset, error.message, error.refusal) from None
    return _CodeVerifier(container).run()


class _CodeVerifier:
    def __init__(self, container: Container) -> None:
        self.container = container
        self.code = container.image.code
        self.base = container.header.code_start  # file offset of code offset 0
        self.instructions: list[isa.Instruction] = []
        self.index_of: dict[int, int] = {}
        self.jumps: list[tuple[int, int]] = []  # (code offset of the ADDR operand, target)

    def fail(self, code_offset: int, message: str, refusal: Refusal) -> VerifyError:
        return VerifyError(self.base + code_offset, f"code offset {code_offset}: {message}",
                           refusal)

    def run(self) -> VerifiedProgram:
        offset = 0
        while offset < len(self.code):
            instruction = self.decode(offset)
            self.index_of[offset] = len(self.instructions)
            self.instructions.append(instruction)
            self.check_operands(instruction)
            offset += instruction.length
        # Falling off the end is allowed: it behaves as (END) (spec/language.md).
        for position, target in self.jumps:
            if target not in self.index_of:
                raise self.fail(position, f"jump target {target} is " + self.misplaced(target),
                                Refusal.BAD_JUMP)
        self.check_handlers()
        self.check_line_map()
        return VerifiedProgram(self.container.image, tuple(self.instructions),
                               self.index_of)

    def decode(self, offset: int) -> isa.Instruction:
        info = isa.OPCODES.get(self.code[offset])
        if info is None:
            raise self.fail(offset, f"unknown opcode 0x{self.code[offset]:02X}",
                            Refusal.UNKNOWN_OPCODE)
        header = self.container.header
        if info.minor > header.minor:  # to a reader of the file's version, it is unknown
            raise self.fail(offset, f"{info.name} is an instruction of format "
                                    f"{header.major}.{info.minor}, but the file says "
                                    f"{header.major}.{header.minor}",
                            Refusal.UNKNOWN_OPCODE)
        if offset + info.length > len(self.code):
            raise self.fail(offset, f"{info.name} needs {info.length} bytes, only "
                                    f"{len(self.code) - offset} remain in the code",
                            Refusal.CUT_OFF)
        return isa.decode_at(self.code, offset)

    def check_operands(self, instruction: isa.Instruction) -> None:
        info = instruction.info
        position = instruction.offset + 1
        values = iter(instruction.operands)
        for operand in info.operands:
            if operand is isa.Operand.VAR:
                self.check_variable(position, next(values), info.name)
                position += 1
            elif operand is isa.Operand.ADDR:
                self.jumps.append((position, next(values)))
                position += 2
            elif operand is isa.Operand.IMM:
                next(values)
                position += 2
            elif operand is isa.Operand.BYTE:
                next(values)
                position += 1
            else:
                self.check_call(instruction, position)
        self.check_feature(instruction)

    def check_variable(self, position: int, index: int, where: str) -> None:
        if index >= len(VARIABLES):
            raise self.fail(position, f"{where}: variable index {index} is out of range "
                                      f"0..{len(VARIABLES) - 1}", Refusal.BAD_VARIABLE)

    def check_call(self, instruction: isa.Instruction, mask_position: int) -> None:
        info = instruction.info
        form = info.form
        assert form is not None  # only call instructions have an ARGS operand
        mask = self.code[mask_position]
        if mask >> info.arity:
            raise self.fail(mask_position, f"{info.name}: argument mask 0x{mask:02X} marks "
                                           f"arguments beyond its {info.arity}",
                            Refusal.BAD_MASK)
        for index, (arg, param) in enumerate(zip(instruction.args, form.params, strict=True)):
            position = mask_position + 1 + info.arg_size * index
            if arg.is_var:
                self.check_variable(position, arg.value, f"{info.name} argument {param.name}")
            elif not param.low <= arg.value <= param.high:
                raise self.fail(position, f"{info.name} argument {param.name} = {arg.value} "
                                          f"is out of range {param.low}..{param.high}",
                                Refusal.ARGUMENT_RANGE)

    def check_feature(self, instruction: isa.Instruction) -> None:
        # The header's features are what a device checks before loading; a call outside
        # them would be a promise the file breaks.
        if instruction.info.builtin is None:
            return
        feature = BUILTINS[instruction.info.builtin[0]].feature
        if feature is not None and feature not in self.container.image.features:
            raise self.fail(instruction.offset, f"{instruction.info.name} needs the device "
                                                f"feature {feature.name}, which the "
                                                "features section does not list",
                            Refusal.MISSING_FEATURE)

    def misplaced(self, target: int) -> str:
        """Why code offset `target` is not an instruction boundary."""
        if target >= len(self.code):
            return f"outside the {len(self.code)}-byte code"
        start = max(offset for offset in self.index_of if offset < target)
        return f"in the middle of the instruction at {start}"

    def check_handlers(self) -> None:
        header = self.container.header
        for index, label in enumerate(HANDLER_LABELS):
            target = self.container.image.handlers.get(label)
            if target is not None and target not in self.index_of:
                raise VerifyError(header.handler_start + 2 * index,
                                  f"handler :{label} at code offset {target} is "
                                  + self.misplaced(target), Refusal.BAD_HANDLER)

    def check_line_map(self) -> None:
        debug = self.container.image.debug
        if debug is None:
            return
        for (offset, _line), position in zip(debug.lines,
                                             self.container.line_entry_offsets, strict=True):
            if offset not in self.index_of:
                raise VerifyError(position, f"line entry for code offset {offset} is "
                                            + self.misplaced(offset),
                                  Refusal.BAD_LINE_ENTRY)
