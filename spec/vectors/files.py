"""The verifier vectors: .ilc files built byte by byte, each with what spec/ilc.md section
10 says a loader does with it: accept it, or refuse it by a numbered rule at a file
offset.

The files are built here with struct and zlib from the layout of spec/ilc.md sections
2-4, sharing no code with vm/ilc.py, so that the encoder and the verifier are checked
against the spec rather than against each other. Most are the file of section 6 (the
program `A=5`, `(MOV 3,A)`) with one thing changed.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass
from typing import Any

# The code of spec/ilc.md section 6: LDI 5 (0), STV A (3), MOV 3,A (5), END (11).
CODE = bytes.fromhex("020500" "0400" "440203000000" "00")
NAME = b"t.rob"
ENTRIES = bytes.fromhex("0001" "0300" "0201" "0600")  # (0, 1) (3, 1) (5, 2) (11, 2)
ABSENT = (0xFFFF,) * 4
MOTION = 0x01


def debug_section(name: bytes = NAME, count: int = 4, entries: bytes = ENTRIES) -> bytes:
    return bytes([len(name)]) + name + struct.pack("<H", count) + entries


def ilc_file(code: bytes = CODE, *, handlers: tuple[int, ...] = ABSENT,
             features: int = MOTION, debug: bytes | None = None, minor: int = 0,
             flags: int = 0, header_extra: bytes = b"", trailing: bytes = b"",
             sizes: dict[str, int] | None = None, crc: int | None = None) -> bytes:
    """A file of this layout; `sizes` overrides header fields (header, code, handler,
    feature, debug), `crc` the CRC (computed as section 3 says when None)."""
    debug = debug_section() if debug is None else debug
    fields = {"header": 24 + len(header_extra), "code": len(code), "handler": 8,
              "feature": 2, "debug": len(debug)} | (sizes or {})
    header = struct.pack("<4sBBHIHHHHI", b"RLIC", 1, minor, flags, 0, fields["header"],
                         fields["code"], fields["handler"], fields["feature"],
                         fields["debug"])
    data = bytearray(header + header_extra + code + struct.pack("<4H", *handlers)
                     + struct.pack("<H", features) + debug + trailing)
    struct.pack_into("<I", data, 8, zlib.crc32(bytes(data)) if crc is None else crc)
    return bytes(data)


def with_crc(data: bytes) -> bytes:
    out = bytearray(data)
    out[8:12] = bytes(4)
    struct.pack_into("<I", out, 8, zlib.crc32(bytes(out)))
    return bytes(out)


BASE = ilc_file()
# MOVV 0 1; MOVI 2 5; MOVR 3; DJGT 0 0; SJZ 1 0; SJGT 1 0; SJLT 1 0; END (version 1.2)
FUSED = bytes.fromhex("070001" "08020500" "0903" "34000000" "35010000" "36010000"
                      "37010000" "00")
DIGEST = bytes(range(0xA0, 0xB0))  # a version 1.1 source digest (section 4.5)
DEBUG = 46  # the debug section's file offset in BASE
ENTRY = DEBUG + 1 + len(NAME) + 2  # the first line entry's file offset


@dataclass(frozen=True)
class FileCase:
    name: str
    covers: str
    data: bytes
    rule: int | None = None  # the rule of spec/ilc.md section 10 that refuses it; None: accepted
    offset: int | None = None  # the file offset the refusal points at

    def vector(self) -> dict[str, Any]:
        return {"name": self.name, "covers": self.covers, "ilc": self.data.hex(),
                "accepted": self.rule is None, "rule": self.rule or 0,
                "offset": -1 if self.offset is None else self.offset}


def _code(code: bytes, features: int = MOTION) -> bytes:
    return ilc_file(code, features=features, debug=b"")


def refused() -> list[FileCase]:
    mov = bytes.fromhex("44")
    return [
        FileCase("short-file", "5 bytes: too short to hold the magic and version",
                 BASE[:5], 1, 5),
        FileCase("bad-magic", "the magic is not RLIC", b"RLIX" + BASE[4:], 1, 0),
        FileCase("newer-major", "major version 2, checked before the rest of the header",
                 BASE[:4] + b"\x02" + BASE[5:12], 2, 4),
        FileCase("short-header", "20 bytes: the header is cut off", BASE[:20], 3, 20),
        FileCase("header-size-small", "header_size 23", ilc_file(sizes={"header": 23}), 4, 12),
        FileCase("header-size-same-minor", "header_size 26 in a 1.0 file",
                 ilc_file(header_extra=b"\0\0"), 4, 12),
        FileCase("handler-size", "handler_size 6", ilc_file(sizes={"handler": 6}), 5, 16),
        FileCase("feature-size", "feature_size 4", ilc_file(sizes={"feature": 4}), 5, 18),
        FileCase("both-sizes", "order: handler_size and feature_size both wrong: "
                 "handler_size is reported", ilc_file(sizes={"handler": 6, "feature": 4}), 5,
                 16),
        FileCase("truncated", "the last byte of the debug section is missing",
                 BASE[:-1], 6, len(BASE) - 1),
        FileCase("size-overflow", "debug_size so large that header_size + code_size + 10 + "
                 "debug_size wraps a u32 to 30, inside a newer minor version's file: "
                 "truncated, not accepted",
                 ilc_file(minor=4, sizes={"debug": 2**32 - 46 + 30}), 6, len(BASE)),
        FileCase("digest-truncated", "a version 1.1 file whose source digest is cut short",
                 ilc_file(minor=1, trailing=DIGEST[:10]), 6, len(BASE) + 10),
        FileCase("extra-byte", "a byte after the last section of a 1.0 file",
                 ilc_file(trailing=b"\0"), 7, len(BASE)),
        FileCase("bad-crc", "the CRC does not match", ilc_file(crc=0x12345678), 8, 8),
        FileCase("crc-before-flags", "order: a bad CRC and an unknown required flag: the CRC",
                 ilc_file(flags=1, crc=0), 8, 8),
        FileCase("required-flag", "required flag bit 0, unknown in 1.0", ilc_file(flags=1),
                 9, 6),
        FileCase("handler-outside", "the :97 entry is code_size, outside the code",
                 ilc_file(handlers=(0xFFFF, 12, 0xFFFF, 0xFFFF)), 10, 38),
        FileCase("feature-bit-7", "feature bit 7, unknown", ilc_file(features=0x81), 11, 44),
        FileCase("name-overlong", "the source name holds C0 80, an overlong NUL",
                 ilc_file(debug=debug_section(b"t\xc0\x80.b")), 12, DEBUG + 2),
        FileCase("name-surrogate", "the source name holds ED A0 80, a surrogate",
                 ilc_file(debug=debug_section(b"ab\xed\xa0\x80")), 12, DEBUG + 3),
        FileCase("name-continuation", "the source name holds a stray continuation byte",
                 ilc_file(debug=debug_section(b"ab\x80")), 12, DEBUG + 3),
        FileCase("name-cut", "the source name ends inside a 3-byte sequence",
                 ilc_file(debug=debug_section(b"ab\xe2\x82")), 12, DEBUG + 3),
        FileCase("name-past-section", "name_size runs past the debug section",
                 ilc_file(debug=b"\x40t.rob"), 12, DEBUG + 1),
        FileCase("leb-not-shortest", "a line entry's number is 80 00, not shortest form",
                 ilc_file(debug=debug_section(count=1, entries=b"\x80\x00\x01")), 12, ENTRY),
        FileCase("leb-too-long", "a number of 4 LEB128 bytes",
                 ilc_file(debug=debug_section(count=1, entries=b"\x80\x80\x80\x01\x01")),
                 12, ENTRY),
        FileCase("offset-repeats", "a line entry with offset_delta 0 after the first",
                 ilc_file(debug=debug_section(count=2, entries=b"\x00\x01\x00\x01")), 12,
                 ENTRY + 2),
        FileCase("line-zero", "a first line entry with line 0",
                 ilc_file(debug=debug_section(count=1, entries=b"\x00\x00")), 12, ENTRY),
        FileCase("left-over", "a byte left over after the last line entry",
                 ilc_file(debug=debug_section(entries=ENTRIES + b"\x00")), 12, ENTRY + 8),
        FileCase("unknown-opcode", "opcode 0x0B is unused", _code(b"\x0b"), 13, 24),
        FileCase("newer-opcode", "MOVV, an instruction of version 1.2, in a 1.1 file",
                 ilc_file(bytes.fromhex("07000100"), debug=b"", minor=1), 13, 24),
        FileCase("fused-variable", "MOVV whose second variable is 53, in a 1.2 file",
                 ilc_file(bytes.fromhex("07003500"), debug=b"", minor=2), 15, 26),
        FileCase("newer-compact-call", "MOVS, a compact call of version 1.3, in a 1.2 file",
                 ilc_file(bytes.fromhex("c40004fc00"), minor=2, debug=b""), 13, 24),
        FileCase("compact-call-without-arguments", "0xC0, FRE's opcode with the compact "
                 "call's bit: FRE has no arguments, so no compact call",
                 ilc_file(bytes.fromhex("c000"), minor=3, debug=b""), 13, 24),
        FileCase("compact-variable", "MOVS whose second argument names variable 53",
                 ilc_file(bytes.fromhex("c4020435"), minor=3, debug=b""), 15, 27),
        FileCase("compact-mask", "MOVS's mask marks a third argument",
                 ilc_file(bytes.fromhex("c4040404"), minor=3, debug=b""), 15, 25),
        FileCase("compact-range", "MOVS with a constant argument of -13 (l is -12..12)",
                 ilc_file(bytes.fromhex("c400f304"), minor=3, debug=b""), 15, 26),
        FileCase("compact-cut", "MOVS cut off by the end of the code: it is 4 bytes",
                 ilc_file(bytes.fromhex("c40004"), minor=3, debug=b""), 14, 24),
        FileCase("cut-instruction", "LDI cut off by the end of the code", _code(b"\x02\x05"),
                 14, 24),
        FileCase("variable-operand", "STV with variable index 53", _code(b"\x04\x35"), 15, 25),
        FileCase("mask-bit", "MOV's mask marks a third argument",
                 _code(mov + b"\x04\x00\x00\x00\x00"), 15, 25),
        FileCase("variable-argument", "MOV's second argument names variable 53",
                 _code(mov + b"\x02\x00\x00\x35\x00"), 15, 28),
        FileCase("constant-argument", "MOV l = 13, outside -12..12",
                 _code(mov + b"\x00\x0d\x00\x00\x00"), 15, 26),
        FileCase("missing-feature", "MOV without MOTION in the features section",
                 _code(mov + b"\x00\x00\x00\x00\x00", features=0), 16, 24),
        FileCase("range-before-feature", "order: one call out of range and lacking its "
                 "feature: the range is reported",
                 _code(mov + b"\x00\x0d\x00\x00\x00", features=0), 15, 26),
        FileCase("jump-inside", "a jump into the middle of an instruction",
                 _code(b"\x02\x05\x00\x30\x01\x00"), 17, 28),
        FileCase("jump-past-code", "a jump to the code's end", _code(b"\x30\x03\x00"), 17, 25),
        FileCase("code-before-jumps", "order: a bad jump target, then an unknown opcode "
                 "further on: the opcode, since targets are checked after the whole code",
                 _code(b"\x30\x01\x00\x07"), 13, 27),
        FileCase("handler-inside", "the :96 entry is inside LDI",
                 ilc_file(handlers=(1, 0xFFFF, 0xFFFF, 0xFFFF)), 18, 36),
        FileCase("line-entry-inside", "a line entry at offset 1, inside LDI",
                 ilc_file(debug=debug_section(count=2, entries=b"\x00\x01\x01\x01")), 19,
                 ENTRY + 2),
    ]


def accepted() -> list[FileCase]:
    return [
        FileCase("section-6", "the file of spec/ilc.md section 6", BASE),
        FileCase("stripped", "no debug section", ilc_file(debug=b"")),
        FileCase("empty-code", "an empty code section", _code(b"", features=0)),
        FileCase("version-1.1", "minor version 1: the source digest after the debug section",
                 ilc_file(minor=1, trailing=DIGEST)),
        FileCase("version-1.1-stripped", "minor version 1 without a debug section, so "
                 "without a digest", ilc_file(minor=1, debug=b"")),
        FileCase("version-1.2", "minor version 2: every superinstruction, a debug section "
                 "and its digest", ilc_file(FUSED, features=0, minor=2,
                                            debug=debug_section(count=1, entries=b"\x00\x01"),
                                            trailing=DIGEST)),
        FileCase("version-1.2-stripped", "minor version 2 without a debug section",
                 ilc_file(FUSED, features=0, minor=2, debug=b"")),
        FileCase("version-1.3", "minor version 3: compact calls, a variable and a constant "
                 "of -12 as MOVS's arguments, then a wide MOV",
                 ilc_file(bytes.fromhex("c40100f4" "440000000000" "00"), minor=3,
                          debug=b"")),
        FileCase("newer-minor-header", "minor version 4 with 4 header bytes 1.3 does not "
                 "know", ilc_file(minor=4, header_extra=b"\1\2\3\4", trailing=DIGEST)),
        FileCase("newer-minor-trailing", "minor version 4 with a section after the source "
                 "digest", ilc_file(minor=4, trailing=DIGEST + b"\xaa\xbb\xcc")),
        FileCase("optional-flag", "optional flag bits 8 and 15", ilc_file(flags=0x8100)),
        FileCase("sparse-line-map", "one line entry for four instructions",
                 ilc_file(debug=debug_section(count=1, entries=b"\x00\x01"))),
        FileCase("no-line-entries", "a debug section with a name and no line entries",
                 ilc_file(debug=debug_section(count=0, entries=b""))),
        FileCase("utf8-name", "a source name in strict UTF-8 of 2, 3 and 4 bytes",
                 ilc_file(debug=debug_section("é走😀.rob".encode()))),
        FileCase("unused-features", "features listed that no call needs",
                 ilc_file(features=0x7F)),
    ]


def all_file_cases() -> list[FileCase]:
    return refused() + accepted()
