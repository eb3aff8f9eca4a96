"""The .ilc container: a fixed header, then the code, handler, features and debug sections.

spec/ilc.md describes the format to the byte; this module is its executable form.
`decode` checks the container only (magic, version, flags, section lengths, CRC, the
syntax of each section). What the code section says (opcodes, operands, jump targets)
is the verifier's business (verifier.py).

The layout is chosen for a C loader on a 16-bit microcontroller: a fixed-size header of
u16 lengths, sections in a fixed order, little-endian, no alignment, nothing to allocate.
"""

from __future__ import annotations

import dataclasses
import struct
import zlib
from dataclasses import dataclass

from .language import HANDLER_LABELS, Feature

MAGIC = b"RLIC"
# The newest version this module reads. A writer writes the oldest minor version whose
# instructions the code uses (Image.minor; vm/isa.py says which instruction came when).
VERSION_MAJOR, VERSION_MINOR = 1, 1

# magic, major, minor, flags, crc, header size, then the size of each section in order.
# The debug section's size is a u32: one entry per instruction can pass 64 KiB.
HEADER = struct.Struct("<4sBBHIHHHHI")
FLAGS_OFFSET = 6
CRC_OFFSET = 8  # the CRC-32 field; it counts as zero while the CRC is computed
HANDLER_SIZE = 2 * len(HANDLER_LABELS)
FEATURE_SIZE = 2
ABSENT = 0xFFFF  # a handler table entry for a label the program does not define
MAX_CODE_SIZE = 0xFFFF  # code offsets are u16
MAX_LINE_ENTRIES = 0xFFFF  # the debug section's entry count is a u16
MAX_LINE = 0xFFFF  # source lines are u16, from 1
MAX_NAME_SIZE = 255  # the debug source name's length is one byte
MAX_VARINT_SIZE = 3  # 3 x 7 bits hold any u16

# Flag bits 0-7 are required: a reader that does not know one refuses the file.
# Bits 8-15 are optional: a reader ignores those it does not know. Version 1.0 defines none.
REQUIRED_FLAGS = 0x00FF
KNOWN_FLAGS = 0x0000


class IlcFormatError(Exception):
    """A file that is not a valid .ilc container; `offset` is a byte offset in the file."""

    def __init__(self, offset: int, message: str) -> None:
        super().__init__(f"byte {offset}: {message}")
        self.offset = offset
        self.message = message


@dataclass(frozen=True)
class DebugInfo:
    source_name: str
    lines: tuple[tuple[int, int], ...]  # (code offset, source line), one per instruction

    def line_at(self, offset: int) -> int | None:
        """The source line of the instruction at or before code `offset`."""
        line = None
        for start, source_line in self.lines:
            if start > offset:
                break
            line = source_line
        return line


@dataclass(frozen=True)
class Image:
    code: bytes
    handlers: dict[int, int]  # handler label 96..99 -> code offset; absent labels left out
    features: frozenset[Feature]
    debug: DebugInfo | None = None
    flags: int = 0  # the header's flag bits, kept so that a file reads back as it was
    minor: int = 0  # the format minor version the file says


@dataclass(frozen=True)
class Header:
    major: int
    minor: int
    flags: int
    crc: int
    header_size: int
    code_size: int
    handler_size: int
    feature_size: int
    debug_size: int

    @property
    def code_start(self) -> int:
        return self.header_size

    @property
    def handler_start(self) -> int:
        return self.code_start + self.code_size

    @property
    def feature_start(self) -> int:
        return self.handler_start + self.handler_size

    @property
    def debug_start(self) -> int:
        return self.feature_start + self.feature_size

    @property
    def end(self) -> int:
        return self.debug_start + self.debug_size


@dataclass(frozen=True)
class Container:
    """A decoded file: its header, its image, and where each debug line entry starts in
    the file (so that the verifier can point at a bad entry)."""

    header: Header
    image: Image
    line_entry_offsets: tuple[int, ...]


def crc_of(data: bytes) -> int:
    """CRC-32 (zlib's polynomial) of the whole file with the CRC field taken as zero."""
    crc = zlib.crc32(data[:CRC_OFFSET])
    crc = zlib.crc32(b"\0\0\0\0", crc)
    return zlib.crc32(data[CRC_OFFSET + 4:], crc)


# --- writing -------------------------------------------------------------------------

def encode(image: Image) -> bytes:
    """The .ilc bytes of `image`; ValueError if the image breaks a limit of the format."""
    if len(image.code) > MAX_CODE_SIZE:
        raise ValueError(f"code is {len(image.code)} bytes; the format allows {MAX_CODE_SIZE}")
    handlers = _encode_handlers(image.handlers, len(image.code))
    features = struct.pack("<H", sum(1 << feature.value for feature in image.features))
    debug = b"" if image.debug is None else _encode_debug(image.debug)
    if not 0 <= image.minor <= 0xFF:
        raise ValueError(f"minor version {image.minor} does not fit its byte")
    if not 0 <= image.flags <= 0xFFFF:
        raise ValueError(f"flags 0x{image.flags:X} do not fit the 16-bit field")
    header = HEADER.pack(MAGIC, VERSION_MAJOR, image.minor, image.flags, 0, HEADER.size,
                         len(image.code), len(handlers), len(features), len(debug))
    data = bytearray(header + image.code + handlers + features + debug)
    struct.pack_into("<I", data, CRC_OFFSET, crc_of(bytes(data)))
    return bytes(data)


def _encode_handlers(handlers: dict[int, int], code_size: int) -> bytes:
    unknown = set(handlers) - set(HANDLER_LABELS)
    if unknown:
        raise ValueError(f"handler labels must be 96..99, not {sorted(unknown)}")
    for label, offset in handlers.items():
        if not 0 <= offset < code_size:
            raise ValueError(f"handler :{label} at {offset} is outside the code")
    return b"".join(struct.pack("<H", handlers.get(label, ABSENT)) for label in HANDLER_LABELS)


def _encode_debug(debug: DebugInfo) -> bytes:
    name = debug.source_name.encode("utf-8")
    if len(name) > MAX_NAME_SIZE:
        raise ValueError(f"source name is {len(name)} bytes; the format allows {MAX_NAME_SIZE}")
    if len(debug.lines) > MAX_LINE_ENTRIES:
        raise ValueError(f"{len(debug.lines)} line entries; the format allows "
                         f"{MAX_LINE_ENTRIES}")
    out = bytearray([len(name)]) + name + struct.pack("<H", len(debug.lines))
    previous_offset, previous_line = 0, 0
    for index, (offset, line) in enumerate(debug.lines):
        if not (0 <= offset <= MAX_CODE_SIZE and 1 <= line <= MAX_LINE):
            raise ValueError(f"line entry {(offset, line)}: offsets are u16, "
                             f"lines 1..{MAX_LINE}")
        if index and offset <= previous_offset:
            raise ValueError(f"line entry {(offset, line)}: offsets must increase")
        if line < previous_line:
            raise ValueError(f"line entry {(offset, line)}: lines must not decrease")
        out += _varint(offset - previous_offset) + _varint(line - previous_line)
        previous_offset, previous_line = offset, line
    return bytes(out)


def _varint(value: int) -> bytes:
    """Unsigned LEB128: 7 bits a byte, low bits first, bit 7 set on all but the last."""
    out = bytearray()
    while value >= 0x80:
        out.append(value & 0x7F | 0x80)
        value >>= 7
    out.append(value)
    return bytes(out)


def strip_debug(image: Image) -> Image:
    return dataclasses.replace(image, debug=None)


# --- reading -------------------------------------------------------------------------

def decode(data: bytes) -> Image:
    """The image in `data`; IlcFormatError if the container is not valid."""
    return read(data).image


def read(data: bytes) -> Container:
    header = read_header(data)
    if crc_of(data) != header.crc:
        raise IlcFormatError(CRC_OFFSET, f"CRC-32 mismatch: the header says "
                             f"0x{header.crc:08X}, the file's is 0x{crc_of(data):08X}; "
                             "the file is damaged, compile it again")
    unknown_required = header.flags & REQUIRED_FLAGS & ~KNOWN_FLAGS
    if unknown_required:
        raise IlcFormatError(FLAGS_OFFSET, f"unknown required flag bits 0x{unknown_required:04X}: "
                             "the file needs a newer reader")
    code = data[header.code_start:header.handler_start]
    handlers = _decode_handlers(data, header)
    features = _decode_features(data, header.feature_start)
    debug, entry_offsets = (None, ()) if header.debug_size == 0 else _decode_debug(data, header)
    return Container(header, Image(code, handlers, features, debug, header.flags,
                                   header.minor), entry_offsets)


def read_header(data: bytes) -> Header:
    """The header, with its section lengths checked against the file's size."""
    if len(data) < 6:
        raise IlcFormatError(len(data), f"truncated: {len(data)} bytes is too short "
                             f"for an .ilc header ({HEADER.size} bytes)")
    if data[:4] != MAGIC:
        raise IlcFormatError(0, f"not an .ilc file: it starts with {data[:4]!r}, "
                             f"not {MAGIC!r}")
    if data[4] != VERSION_MAJOR:
        raise IlcFormatError(4, f"format version {data[4]}.{data[5]} is not supported: "
                             f"this reader reads version {VERSION_MAJOR}.x")
    if len(data) < HEADER.size:
        raise IlcFormatError(len(data), f"truncated: {len(data)} bytes is too short "
                             f"for an .ilc header ({HEADER.size} bytes)")
    header = Header(*HEADER.unpack_from(data)[1:])
    newer = header.minor > VERSION_MINOR
    if header.header_size < HEADER.size or (header.header_size != HEADER.size and not newer):
        raise IlcFormatError(12, f"header size {header.header_size} is wrong: "
                             f"version {header.major}.{header.minor} has {HEADER.size}")
    for field_offset, size, expected, what in ((16, header.handler_size, HANDLER_SIZE,
                                                "handler table"),
                                               (18, header.feature_size, FEATURE_SIZE,
                                                "features")):
        if size != expected:
            raise IlcFormatError(field_offset, f"the {what} section must be {expected} "
                                 f"bytes, the header says {size}")
    if header.end > len(data):
        raise IlcFormatError(len(data), f"truncated: the header's section sizes add up "
                             f"to {header.end} bytes, the file has {len(data)}")
    if header.end < len(data) and not newer:
        raise IlcFormatError(header.end, f"{len(data) - header.end} unexpected bytes "
                             "after the last section")
    return header


def _decode_handlers(data: bytes, header: Header) -> dict[int, int]:
    handlers: dict[int, int] = {}
    for index, label in enumerate(HANDLER_LABELS):
        position = header.handler_start + 2 * index
        (offset,) = struct.unpack_from("<H", data, position)
        if offset == ABSENT:
            continue
        if offset >= header.code_size:
            raise IlcFormatError(position, f"handler :{label} points at code offset "
                                 f"{offset}, outside the {header.code_size}-byte code")
        handlers[label] = offset
    return handlers


def _decode_features(data: bytes, position: int) -> frozenset[Feature]:
    (mask,) = struct.unpack_from("<H", data, position)
    known = sum(1 << feature.value for feature in Feature)
    if mask & ~known:
        raise IlcFormatError(position, f"unknown feature bits 0x{mask & ~known:04X}: the "
                             "program needs a device feature this reader does not know")
    return frozenset(feature for feature in Feature if mask >> feature.value & 1)


def _decode_debug(data: bytes, header: Header) -> tuple[DebugInfo, tuple[int, ...]]:
    reader = _Reader(data, header.debug_start, header.end, "debug section")
    name_bytes = reader.take(reader.byte())
    try:
        name = name_bytes.decode("utf-8")
    except UnicodeDecodeError as error:
        raise IlcFormatError(header.debug_start + 1 + error.start,
                             "the debug source name is not UTF-8") from None
    count = reader.u16()
    lines: list[tuple[int, int]] = []
    starts: list[int] = []
    offset, line = 0, 0
    for index in range(count):
        start = reader.position
        offset_delta, line_delta = reader.varint(), reader.varint()
        if index and offset_delta == 0:
            raise IlcFormatError(start, "line entry repeats the previous entry's code offset")
        offset, line = offset + offset_delta, line + line_delta
        if offset > MAX_CODE_SIZE or line > MAX_LINE or line == 0:
            raise IlcFormatError(start, f"line entry (offset {offset}, line {line}) is out "
                                 f"of range: offsets are u16, lines 1..{MAX_LINE}")
        lines.append((offset, line))
        starts.append(start)
    if reader.position != header.end:
        raise IlcFormatError(reader.position, f"{header.end - reader.position} bytes left "
                             "over at the end of the debug section")
    return DebugInfo(name, tuple(lines)), tuple(starts)


class _Reader:
    """Reads the fields of one section, refusing to run past its end."""

    def __init__(self, data: bytes, start: int, end: int, what: str) -> None:
        self.data, self.position, self.end, self.what = data, start, end, what

    def take(self, size: int) -> bytes:
        if self.position + size > self.end:
            raise IlcFormatError(self.position, f"the {self.what} ends in the middle of a "
                                 f"field ({size} bytes needed, {self.end - self.position} left)")
        chunk = self.data[self.position:self.position + size]
        self.position += size
        return chunk

    def byte(self) -> int:
        return self.take(1)[0]

    def u16(self) -> int:
        value: int = struct.unpack("<H", self.take(2))[0]
        return value

    def varint(self) -> int:
        start, value = self.position, 0
        for index in range(MAX_VARINT_SIZE):
            byte = self.byte()
            value |= (byte & 0x7F) << 7 * index
            if not byte & 0x80:
                if index and not byte:
                    # Only the shortest form is valid, so that every image has one encoding.
                    raise IlcFormatError(start, f"a number in the {self.what} is not in "
                                         "its shortest form (a trailing zero byte)")
                return value
        raise IlcFormatError(start, f"a number in the {self.what} is longer than "
                             f"{MAX_VARINT_SIZE} bytes")
