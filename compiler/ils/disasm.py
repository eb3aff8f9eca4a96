"""`rl1c dis`: an .ilc file as .ils text, which `rl1c asm` reads back to the same bytes.

The header and the section layout are shown as comments (the assembler derives them);
the features, the handler table, the source name and digest and the line map are
directives; each instruction shows its code offset. Jump and handler targets get labels
named after their offsets (`L0042`). With the program's source at hand, its lines are
interleaved as comments, like `objdump -S`.
"""

from __future__ import annotations

import json
from collections.abc import Sequence

from rl1.vm import ilc, isa
from rl1.vm.language import HANDLER_LABELS, VARIABLES, Feature
from rl1.vm.verifier import verify


def label_name(offset: int) -> str:
    return f"L{offset:04d}"


def disassemble(data: bytes, name: str, source_lines: Sequence[str] | None = None) -> str:
    """The .ils text of the .ilc bytes `data` (read from file `name`), with the lines of
    its source interleaved when given (sources.find_source finds them). VerifyError if
    the file does not verify: only verified code has known instruction boundaries."""
    program = verify(data)
    header = ilc.read_header(data)
    image = program.image
    if image.debug is None:
        source_lines = None
    out = [*_header_comments(header, name, len(data)), _features(image.features)]
    if image.flags:
        out.append(f".flags ${image.flags:04X}")
    out += [f".handler {label} "
            + (label_name(image.handlers[label]) if label in image.handlers else "none")
            for label in HANDLER_LABELS]
    entries: dict[int, int] = {}
    if image.debug is not None:
        out.append(f".source {json.dumps(image.debug.source_name, ensure_ascii=False)}")
        if image.debug.source_digest is not None:
            out.append(f'.digest "{image.debug.source_digest.hex()}"')
        entries = dict(image.debug.lines)
    targets = set(image.handlers.values()) | {
        instruction.operands[-1] for instruction in program.instructions
        if isa.Operand.ADDR in instruction.info.operands
    }
    out.append("")
    current_line: int | None = None
    last_shown = 0
    for instruction in program.instructions:
        line = entries.get(instruction.offset)
        if line is None and current_line is not None:
            out.append("        .line none")
        elif line is not None and line != current_line:
            if source_lines is not None:
                out += [f"        ; {number:4d} | {source_lines[number - 1]}".rstrip()
                        for number in range(last_shown + 1, min(line, len(source_lines)) + 1)]
                last_shown = max(last_shown, line)
            out.append(f"        .line {line}")
        current_line = line
        if instruction.offset in targets:
            out.append(label_name(instruction.offset) + ":")
        out.append(f"  {instruction.offset:04d}  {render(instruction)}")
    return "\n".join(out) + "\n"


def render(instruction: isa.Instruction) -> str:
    """One instruction in .ils syntax, without its offset."""
    values = iter(instruction.operands)
    operands: list[str] = []
    for operand in instruction.info.operands:
        if operand is isa.Operand.VAR:
            operands.append(VARIABLES[next(values)])
        elif operand in (isa.Operand.IMM, isa.Operand.BYTE):
            operands.append(str(next(values)))
        elif operand is isa.Operand.ADDR:
            operands.append(label_name(next(values)))
        else:
            operands += [VARIABLES[arg.value] if arg.is_var else str(arg.value)
                         for arg in instruction.args]
    name = instruction.info.name
    return f"{name} {', '.join(operands)}" if operands else name


def _header_comments(header: ilc.Header, name: str, size: int) -> list[str]:
    lines = [
        f"; {name}: RL/I intermediate code, format {header.major}.{header.minor}, "
        f"flags 0x{header.flags:04X}, CRC-32 0x{header.crc:08X}, {size} bytes",
        f"; sections (file offset: size): header 0: {header.header_size}, "
        f"code {header.code_start}: {header.code_size}, "
        f"handlers {header.handler_start}: {header.handler_size}, "
        f"features {header.feature_start}: {header.feature_size}, "
        f"debug {header.debug_start}: {header.debug_size}",
    ]
    if header.minor > ilc.VERSION_MINOR:
        lines.append(f"; written for a newer format ({header.major}.{header.minor}): "
                     "header fields and sections this reader does not know are not shown")
    return lines


def _features(features: frozenset[Feature]) -> str:
    names = [feature.name for feature in sorted(features, key=lambda f: f.value)]
    return " ".join([".features", *names])
