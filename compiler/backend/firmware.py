"""The bytes of an .ilc file in the forms firmware builds take: a C99 array
(`rl1c --emit c`) and Intel HEX (`rl1c --emit ihex`).

Both carry the .ilc file byte for byte; nothing here knows what the bytes mean.
"""

from __future__ import annotations

import os
import re
from typing import Literal

FirmwareFormat = Literal["c", "ihex"]
FORMATS: tuple[FirmwareFormat, ...] = ("c", "ihex")

_C_KEYWORDS = frozenset({
    "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else",
    "enum", "extern", "float", "for", "goto", "if", "inline", "int", "long", "register",
    "restrict", "return", "short", "signed", "sizeof", "static", "struct", "switch",
    "typedef", "union", "unsigned", "void", "volatile", "while", "_Bool", "_Complex",
    "_Imaginary",
})  # C99's keywords
_C_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_BYTES_PER_C_LINE = 12  # 12 * len("0x00, ") + indent stays under 80 columns
_BYTES_PER_RECORD = 16  # the usual Intel HEX record length, as objcopy writes
ADDRESS_SPACE = 1 << 32  # Intel HEX's extended linear addresses reach 4 GiB


def c_name_problem(name: str) -> str | None:
    """Why `name` cannot name the C array (None: it can)."""
    if not _C_IDENTIFIER.fullmatch(name):
        return (f"`{name}` is not a C identifier: use letters, digits and `_`, not starting "
                "with a digit")
    if name in _C_KEYWORDS:
        return f"`{name}` is a C keyword"
    if name.startswith("_"):
        # C reserves every file-scope identifier that starts with `_`.
        return f"`{name}` starts with `_`, which C reserves for its implementation"
    return None


def c_name_for(stem: str) -> str:
    """The default array name for a program whose file is called `stem` (no directory,
    no extension): `sample` gives `sample_ilc`, `line-1` gives `line_1_ilc`, `1st`
    gives `rl1_1st_ilc`."""
    stem = re.sub(r"[^A-Za-z0-9_]", "_", stem).lstrip("_") or "program"
    return ("rl1_" if stem[0].isdigit() else "") + stem + "_ilc"


def c_source(data: bytes, name: str, source_name: str, progmem: bool = False) -> str:
    """A C99 translation unit defining `const uint8_t NAME[]` (the bytes of `data`) and
    `const uint32_t NAME_size`, its size (rl1_load's type: 32 bits on every target);
    `source_name` is said in the opening comment. The extern declarations come first so
    that another file may copy them as its header (and compilers that warn about
    definitions without one stay quiet).

    With `progmem` the array is `PROGMEM`: in AVR's flash, which is not in the data
    address space, so the loader reads it with pgm_read_byte (vm/c/README.md, AVR) and
    no RAM holds it; on any other target PROGMEM means nothing, so the file builds
    everywhere. The size stays an ordinary constant, read with a plain load."""
    assert c_name_problem(name) is None, name
    rows = [", ".join(f"0x{byte:02x}" for byte in data[start:start + _BYTES_PER_C_LINE])
            for start in range(0, len(data), _BYTES_PER_C_LINE)]
    # A file name cannot end the comment early, and its bytes past ASCII (ロボ.rob, or a
    # name that is not UTF-8) are escaped, so that the file is ASCII for any compiler.
    comment = os.fsencode(source_name).decode("ascii", "backslashreplace").replace("*/", "* /")
    command = "rl1c --emit c --progmem" if progmem else "rl1c --emit c"
    placement = ("#ifdef __AVR__\n"
                 "#include <avr/pgmspace.h> /* PROGMEM: in flash, read with pgm_read_byte */\n"
                 "#endif\n"
                 "#ifndef PROGMEM\n"
                 "#define PROGMEM /* flash and data share one address space */\n"
                 "#endif\n") if progmem else ""
    return (
        f"/* The RL/I program {comment} as .ilc intermediate code ({len(data)} bytes),\n"
        f"   written by {command}. Regenerate it rather than edit it. */\n"
        "#include <stdint.h>\n"
        + placement
        + "\n"
        f"extern const uint8_t {name}[{len(data)}];\n"
        f"extern const uint32_t {name}_size;\n"
        "\n"
        f"const uint8_t {name}[{len(data)}]{' PROGMEM' if progmem else ''} = {{\n"
        + "".join(f"    {row},\n" for row in rows)
        + "};\n"
        f"const uint32_t {name}_size = {len(data)}u;\n"
    )


def intel_hex(data: bytes, base: int) -> str:
    """`data` as Intel HEX records placed from address `base`: data records of up to 16
    bytes that never cross a 64 KiB boundary, an extended linear address record (type
    04) before the first record of each 64 KiB segment other than 0, and the end-of-file
    record. ValueError when the bytes would not fit below 4 GiB."""
    if base < 0 or base + len(data) > ADDRESS_SPACE:
        raise ValueError(f"{len(data)} bytes from address 0x{base:X} reach past 4 GiB, "
                         "the end of Intel HEX's address space")
    records: list[str] = []
    segment = 0
    offset = 0
    while offset < len(data):
        address = base + offset
        if address >> 16 != segment:
            segment = address >> 16
            records.append(_record(0, 0x04, segment.to_bytes(2, "big")))
        room = 0x10000 - (address & 0xFFFF)
        chunk = data[offset:offset + min(_BYTES_PER_RECORD, room)]
        records.append(_record(address & 0xFFFF, 0x00, chunk))
        offset += len(chunk)
    records.append(_record(0, 0x01, b""))
    return "".join(record + "\n" for record in records)


def _record(address: int, kind: int, payload: bytes) -> str:
    body = bytes([len(payload), address >> 8, address & 0xFF, kind]) + payload
    checksum = -sum(body) & 0xFF
    return ":" + (body + bytes([checksum])).hex().upper()
