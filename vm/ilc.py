"""The .ilc container: a fixed header, then the code, handler, features and debug
sections, and (from version 1.1) the digest of the source the debug section describes.

spec/ilc.md describes the format to the byte; this module is its executable form.
`decode` checks the container only (magic, version, flags, section lengths, CRC, the
syntax of each section). What the code section says (opcodes, operands, jump targets)
is the verifier's business (verifier.py).

The layout is chosen for a C loader on a 16-bit microcontroller: a fixed-size header of
u16 lengths, sections in a fixed order, little-endian, no alignment, nothing to allocate.
"""

from __future__ import annotations

import bisect
import dataclasses
import hashlib
import struct
import zlib
from dataclasses import dataclass
from enum import IntEnum
from operator import itemgetter

from . import isa
from .language import HANDLER_LABELS, Feature

MAGIC = b"RLIC"
# The newest version this module reads. A writer writes the oldest minor version that
# holds what the file carries: the source digest came in 1.1, and each instruction's
# version is in vm/isa.py.
VERSION_MAJOR, VERSION_MINOR = 1, 3
DIGEST_MINOR = 1  # the first minor version with the source digest section
DIGEST_SIZE = 16  # the first 16 bytes of SHA-256

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


class Refusal(IntEnum):
    """Why a file is refused: one kind per rule of spec/ilc.md section 10, in the order
    the rules are checked. The C loader's `rl1_refusal` (vm/c/rl1vm.h) has the same names
    (prefixed RL1_) and numbers, so that the two can be compared refusal for refusal."""

    TRUNCATED = 1  # the header or a section passes the file's end
    BAD_MAGIC = 2
    BAD_MAJOR = 3
    BAD_HEADER_SIZE = 4
    BAD_SECTION_SIZE = 5  # the handler table or the features section
    EXTRA_BYTES = 6
    BAD_CRC = 7
    REQUIRED_FLAG = 8
    HANDLER_OUTSIDE = 9  # a handler entry past the code
    UNKNOWN_FEATURE = 10
    DEBUG_CUT_OFF = 11  # a debug field passes the section's end
    DEBUG_NAME_UTF8 = 12
    DEBUG_NUMBER = 13  # a LEB128 number too long or not in its shortest form
    DEBUG_ORDER = 14  # line entry offsets do not increase
    DEBUG_RANGE = 15  # a line entry's offset or line out of range
    DEBUG_LEFTOVER = 16
    UNKNOWN_OPCODE = 17
    CUT_OFF = 18  # an instruction cut off by the code's end
    BAD_VARIABLE = 19
    BAD_MASK = 20
    ARGUMENT_RANGE = 21
    MISSING_FEATURE = 22  # a call whose device feature the header does not list
    BAD_JUMP = 23  # a jump target that does not start an instruction
    BAD_HANDLER = 24  # likewise a handler entry
    BAD_LINE_ENTRY = 25  # likewise a line entry


class IlcFormatError(Exception):
    """A file that is not a valid .ilc container; `offset` is a byte offset in the file,
    `refusal` the rule it breaks."""

    def __init__(self, offset: int, message: str, refusal: Refusal) -> None:
        super().__init__(f"byte {offset}: {message}")
        self.offset = offset
        self.message = message
        self.refusal = refusal


@dataclass(frozen=True)
class DebugInfo:
    source_name: str
    lines: tuple[tuple[int, int], ...]  # (code offset, source line), one per instruction
    # source_digest(text) of the source compiled; None in a version 1.0 file
    source_digest: bytes | None = None

    def line_at(self, offset: int) -> int | None:
        """The source line of the instruction at or before code `offset` (the entries'
        offsets increase: a binary search, as a simulated run asks at every call)."""
        index = bisect.bisect_right(self.lines, offset, key=itemgetter(0))
        return self.lines[index - 1][1] if index else None


def source_digest(text: str) -> bytes:
    """The digest that tells a source from any edited copy: the first 16 bytes of the
    SHA-256 of its text in UTF-8 (as decoded: encoding and BOM do not matter)."""
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).digest()[:DIGEST_SIZE]


@dataclass(frozen=True)
class Image:
    code: bytes
    handlers: dict[int, int]  # handler label 96..99 -> code offset; absent labels left out
    features: frozenset[Feature]
    debug: DebugInfo | None = None
    flags: int = 0  # the header's flag bits, kept so that a file reads back as it was


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
    def digest_start(self) -> int:
        return self.debug_start + self.debug_size

    @property
    def digest_size(self) -> int:
        """The source digest follows a debug section from version 1.1 on."""
        return DIGEST_SIZE if self.minor >= DIGEST_MINOR and self.debug_size else 0

    @property
    def end(self) -> int:
        """Where the sections this reader knows end."""
        return self.digest_start + self.digest_size


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
    digest = b"" if image.debug is None or image.debug.source_digest is None \
        else image.debug.source_digest
    if digest and len(digest) != DIGEST_SIZE:
        raise ValueError(f"a source digest is {DIGEST_SIZE} bytes, not {len(digest)}")
    if not 0 <= image.flags <= 0xFFFF:
        raise ValueError(f"flags 0x{image.flags:X} do not fit the 16-bit field")
    # A file without a digest whose code needs nothing newer is written as 1.0, so that
    # every 1.0 reader reads it.
    minor = max(isa.code_minor(image.code), DIGEST_MINOR if digest else 0)
    if minor >= DIGEST_MINOR and image.debug is not None and not digest:
        raise ValueError(f"a version 1.{minor} file's debug section is followed by the "
                         "source digest, and this image has none")
    header = HEADER.pack(MAGIC, VERSION_MAJOR, minor, image.flags, 0, HEADER.size,
                         len(image.code), len(handlers), len(features), len(debug))
    data = bytearray(header + image.code + handlers + features + debug + digest)
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


def debug_source_name(name: str) -> str:
    """The file name `name` as the debug section holds it: UTF-8, each surrogate (a byte
    of a name that is not UTF-8, as Python holds it) as U+FFFD, and within MAX_NAME_SIZE
    bytes (its end kept, where the file's own name is)."""
    encoded = "".join("\ufffd" if "\ud800" <= character <= "\udfff" else character
                      for character in name).encode("utf-8")
    return encoded[-MAX_NAME_SIZE:].decode("utf-8", "ignore")


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
                             "the file is damaged",  # what to do is the reporter's help
                             Refusal.BAD_CRC)
    unknown_required = header.flags & REQUIRED_FLAGS & ~KNOWN_FLAGS
    if unknown_required:
        raise IlcFormatError(FLAGS_OFFSET, f"unknown required flag bits 0x{unknown_required:04X}: "
                             "the file needs a newer reader",
                             Refusal.REQUIRED_FLAG)
    code = data[header.code_start:header.handler_start]
    handlers = _decode_handlers(data, header)
    features = _decode_features(data, header.feature_start)
    debug, entry_offsets = (None, ()) if header.debug_size == 0 else _decode_debug(data, header)
    return Container(header, Image(code, handlers, features, debug, header.flags),
                     entry_offsets)


def wrong_start(data: bytes) -> str:
    """What a file `data` that does not start with MAGIC starts with instead, its bytes
    in hex (a Python bytes repr, b'...', is no user's notation)."""
    return (f"it does not start with `{MAGIC.decode()}` (its first bytes are "
            f"{data[:len(MAGIC)].hex(' ').upper()})")


def read_header(data: bytes) -> Header:
    """The header, with its section lengths checked against the file's size."""
    if len(data) < 6:
        raise IlcFormatError(len(data), f"truncated: {len(data)} bytes is too short "
                             f"for an .ilc header ({HEADER.size} bytes)",
                             Refusal.TRUNCATED)
    if data[:4] != MAGIC:
        raise IlcFormatError(0, f"not an .ilc file: {wrong_start(data)}", Refusal.BAD_MAGIC)
    if data[4] != VERSION_MAJOR:
        raise IlcFormatError(4, f"format version {data[4]}.{data[5]} is not supported: "
                             f"this reader reads version {VERSION_MAJOR}.x",
                             Refusal.BAD_MAJOR)
    if len(data) < HEADER.size:
        raise IlcFormatError(len(data), f"truncated: {len(data)} bytes is too short "
                             f"for an .ilc header ({HEADER.size} bytes)",
                             Refusal.TRUNCATED)
    header = Header(*HEADER.unpack_from(data)[1:])
    newer = header.minor > VERSION_MINOR
    if header.header_size < HEADER.size or (header.header_size != HEADER.size and not newer):
        raise IlcFormatError(12, f"header size {header.header_size} is wrong: "
                             f"version {header.major}.{header.minor} has {HEADER.size}",
                             Refusal.BAD_HEADER_SIZE)
    for field_offset, size, expected, what in ((16, header.handler_size, HANDLER_SIZE,
                                                "handler table"),
                                               (18, header.feature_size, FEATURE_SIZE,
                                                "features")):
        if size != expected:
            raise IlcFormatError(field_offset, f"the {what} section must be {expected} "
                                 f"bytes, the header says {size}",
                                 Refusal.BAD_SECTION_SIZE)
    if header.end > len(data):
        raise IlcFormatError(len(data), f"truncated: the header's section sizes add up "
                             f"to {header.end} bytes, the file has {len(data)}",
                             Refusal.TRUNCATED)
    if header.end < len(data) and not newer:
        raise IlcFormatError(header.end, f"{len(data) - header.end} unexpected bytes "
                             "after the last section",
                             Refusal.EXTRA_BYTES)
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
                                 f"{offset}, outside the {header.code_size}-byte code",
                                 Refusal.HANDLER_OUTSIDE)
        handlers[label] = offset
    return handlers


def _decode_features(data: bytes, position: int) -> frozenset[Feature]:
    (mask,) = struct.unpack_from("<H", data, position)
    known = sum(1 << feature.value for feature in Feature)
    if mask & ~known:
        raise IlcFormatError(position, f"unknown feature bits 0x{mask & ~known:04X}: the "
                             "program needs a device feature this reader does not know",
                             Refusal.UNKNOWN_FEATURE)
    return frozenset(feature for feature in Feature if mask >> feature.value & 1)


def _decode_debug(data: bytes, header: Header) -> tuple[DebugInfo, tuple[int, ...]]:
    reader = _Reader(data, header.debug_start, header.digest_start, "debug section")
    name_bytes = reader.take(reader.byte())
    try:
        name = name_bytes.decode("utf-8")
    except UnicodeDecodeError as error:
        raise IlcFormatError(header.debug_start + 1 + error.start,
                             "the debug source name is not UTF-8",
                             Refusal.DEBUG_NAME_UTF8) from None
    count = reader.u16()
    lines: list[tuple[int, int]] = []
    starts: list[int] = []
    offset, line = 0, 0
    for index in range(count):
        start = reader.position
        offset_delta, line_delta = reader.varint(), reader.varint()
        if index and offset_delta == 0:
            raise IlcFormatError(start, "line entry repeats the previous entry's code offset",
                                 Refusal.DEBUG_ORDER)
        offset, line = offset + offset_delta, line + line_delta
        if offset > MAX_CODE_SIZE or line > MAX_LINE or line == 0:
            raise IlcFormatError(start, f"line entry (offset {offset}, line {line}) is out "
                                 f"of range: offsets are u16, lines 1..{MAX_LINE}",
                                 Refusal.DEBUG_RANGE)
        lines.append((offset, line))
        starts.append(start)
    if reader.position != header.digest_start:
        raise IlcFormatError(reader.position, f"{header.digest_start - reader.position} "
                             "bytes left over at the end of the debug section",
                             Refusal.DEBUG_LEFTOVER)
    digest = data[header.digest_start:header.end] if header.digest_size else None
    return DebugInfo(name, tuple(lines), digest), tuple(starts)


class _Reader:
    """Reads the fields of one section, refusing to run past its end."""

    def __init__(self, data: bytes, start: int, end: int, what: str) -> None:
        self.data, self.position, self.end, self.what = data, start, end, what

    def take(self, size: int) -> bytes:
        if self.position + size > self.end:
            raise IlcFormatError(self.position, f"the {self.what} ends in the middle of a "
                                 f"field ({size} bytes needed, {self.end - self.position} left)",
                                 Refusal.DEBUG_CUT_OFF)
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
                                         "its shortest form (a trailing zero byte)",
                                         Refusal.DEBUG_NUMBER)
                return value
        raise IlcFormatError(start, f"a number in the {self.what} is longer than "
                             f"{MAX_VARINT_SIZE} bytes",
                             Refusal.DEBUG_NUMBER)
