"""spec/ilc.md agrees with the code it describes: the instruction table with isa.OPCODES,
the header table with the header the writer writes, and the byte-by-byte example with
what the compiler produces."""

from __future__ import annotations

import dataclasses
import re
import struct

from support import ROOT

from rl1.compiler.backend.driver import compile_text
from rl1.vm import ilc, isa, isa_table
from rl1.vm.language import Feature

SPEC = (ROOT / "spec" / "ilc.md").read_text(encoding="utf-8")


def table_after(heading: str) -> list[list[str]]:
    """The cells of the first table whose header row starts with `heading`."""
    lines = SPEC[SPEC.index(heading):].splitlines()
    rows = []
    for line in lines[2:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in re.split(r"(?<!\\)\|", line.strip("|"))])
    return rows


def test_the_instruction_table_is_the_generated_one() -> None:
    assert isa_table.render() in SPEC, (
        "spec/ilc.md's instruction table differs from vm/isa.py: regenerate it with "
        "`python -m rl1.vm.isa_table` and paste it between the markers")


def test_the_instruction_table_lists_every_opcode_exactly() -> None:
    rows = table_after("| opcode | mnemonic |")
    assert len(rows) == len(isa.OPCODES)
    for opcode, name, _operands, length, meaning, *_ in rows:
        info = isa.OPCODES[int(opcode, 16)]
        assert (name, int(length), meaning.replace("\\|", "|")) == (
            info.name, info.length, info.meaning)


def test_the_header_table_matches_the_header_struct() -> None:
    rows = table_after("| offset | size | field | meaning |")
    sizes = {"u8": 1, "u16": 2, "u32": 4}
    offsets = [int(offset) for offset, _, _, _ in rows]
    widths = [sizes.get(size) or int(size) for _, size, _, _ in rows]
    names = [name.strip("`") for _, _, name, _ in rows]
    # The struct's fields one by one: "<4sBBHIHHHHI" has widths 4, 1, 1, 2, 4, ...
    assert widths == [struct.calcsize("<" + code) for code in
                      re.findall(r"\d*[a-zA-Z]", ilc.HEADER.format[1:])]
    assert offsets == [sum(widths[:index]) for index in range(len(widths))]
    assert names == ["magic", *(field.name for field in dataclasses.fields(ilc.Header))]
    assert offsets[names.index("crc")] == ilc.CRC_OFFSET


def test_the_feature_table_matches_the_feature_numbers() -> None:
    rows = table_after("| bit | feature | built-ins |")
    assert [(int(bit), name) for bit, name, _ in rows] == [
        (feature.value, feature.name) for feature in Feature]


def test_the_byte_by_byte_example_is_what_the_compiler_writes() -> None:
    example = SPEC[SPEC.index("## 6. A file, byte by byte"):SPEC.index("## 7.")]
    dump = example.split("```")[3]  # the second code block: the annotated bytes
    # Each line: "offset: bytes  comment", the comment after two spaces or more.
    data = bytearray()
    for line in dump.strip().splitlines():
        offset, rest = line.split(":", 1)
        assert int(offset) == len(data), f"the line {line!r} is at the wrong offset"
        data += bytes(int(byte, 16) for byte in rest.strip().split("  ")[0].split())
    # -O0: at the default -O1 the MOV takes the constant, and the example shows a variable.
    compiled = compile_text("A=5\n(MOV 3,A)\n", "t.rob", level=0).output
    assert bytes(data) == compiled
