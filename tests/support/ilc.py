"""Test helpers for .ilc files: Hypothesis strategies for valid images (random instruction
sequences whose jumps, handlers and line entries all land on instruction boundaries, with
in-range operands) and for damaged files, and the CRC as the spec defines it."""

from __future__ import annotations

import struct
import zlib

from hypothesis import strategies as st

from rl1.vm import ilc, isa
from rl1.vm.language import BUILTINS, HANDLER_LABELS, VARIABLES, Feature, Param


def with_crc(data: bytes | bytearray) -> bytes:
    """`data` with its CRC field recomputed as the spec defines it, independently of
    the implementation: zlib's CRC-32 of the file with bytes 8..11 taken as zero."""
    out = bytearray(data)
    out[8:12] = bytes(4)
    out[8:12] = struct.pack("<I", zlib.crc32(bytes(out)))
    return bytes(out)


OPCODE_INFOS = sorted(isa.OPCODES.values(), key=lambda info: info.opcode)
CALLS_WITH_ARGUMENTS = [info for info in isa.OPCODES.values()
                        if info.form is not None and info.arity]
"""Every call that takes arguments, full-width and compact."""
variable_indexes = st.integers(0, len(VARIABLES) - 1)


def needed_features(infos: list[isa.OpInfo]) -> set[Feature]:
    builtins = (BUILTINS[info.builtin[0]] for info in infos if info.builtin is not None)
    return {b.feature for b in builtins if b.feature is not None}


@st.composite
def instruction_bytes(draw: st.DrawFn, info: isa.OpInfo, offsets: list[int]) -> bytes:
    operands: list[int] = []
    for operand in info.operands:
        if operand is isa.Operand.VAR:
            operands.append(draw(variable_indexes))
        elif operand is isa.Operand.IMM:
            operands.append(draw(st.integers(-0x8000, 0x7FFF)))
        elif operand is isa.Operand.BYTE:
            operands.append(draw(st.integers(-0x80, 0x7F)))
        elif operand is isa.Operand.ADDR:
            operands.append(draw(st.sampled_from(offsets)))
    form = info.form
    params = form.params if form is not None else ()
    args = tuple(
        isa.Arg(True, draw(variable_indexes)) if draw(st.booleans())
        else isa.Arg(False, draw(st.integers(*_constant_range(param, info))))
        for param in params
    )
    return isa.encode(info, tuple(operands), args)


def _constant_range(param: Param, call: isa.OpInfo) -> tuple[int, int]:
    """A constant argument's range: its parameter's, within a byte in a compact call."""
    if call.compact:
        return max(param.low, -0x80), min(param.high, 0x7F)
    return param.low, param.high


@st.composite
def debug_infos(draw: st.DrawFn, offsets: list[int], digested: bool) -> ilc.DebugInfo:
    """A debug section; `digested`: with a source digest (a file of version 1.2 has
    one), else perhaps."""
    name = draw(st.text(max_size=20))
    covered = [offset for offset in offsets if draw(st.integers(0, 4))]  # most, not all
    line = draw(st.integers(1, 100))
    lines: list[tuple[int, int]] = []
    for offset in covered:
        lines.append((offset, line))
        # Mostly small steps; sometimes large ones, for the multi-byte numbers.
        line = min(ilc.MAX_LINE, line + draw(st.integers(0, 3) | st.integers(0, 40000)))
    some_digest = st.binary(min_size=ilc.DIGEST_SIZE, max_size=ilc.DIGEST_SIZE)
    digest = draw(some_digest if digested else st.none() | some_digest)
    return ilc.DebugInfo(name, tuple(lines), digest)


@st.composite
def images(draw: st.DrawFn, max_instructions: int = 25) -> ilc.Image:
    infos = draw(st.lists(st.sampled_from(OPCODE_INFOS), max_size=max_instructions))
    offsets: list[int] = []
    size = 0
    for info in infos:
        offsets.append(size)
        size += info.length
    code = b"".join(draw(instruction_bytes(info, offsets)) for info in infos)
    handlers = draw(st.dictionaries(st.sampled_from(list(HANDLER_LABELS)),
                                    st.sampled_from(offsets))) if offsets else {}
    extra = draw(st.frozensets(st.sampled_from(list(Feature))))
    features = frozenset(needed_features(infos)) | extra
    debug = draw(st.none() | debug_infos(offsets, isa.code_minor(code) >= ilc.DIGEST_MINOR))
    optional_flags = draw(st.integers(0, 0xFF)) << 8  # a reader must accept unknown ones
    return ilc.Image(code, handlers, features, debug, optional_flags)


# --- damage of every kind ------------------------------------------------------------

HEADER_FIELDS = [(4, "<B"), (5, "<B"), (6, "<H"), (12, "<H"), (14, "<H"), (16, "<H"),
                 (18, "<H"), (20, "<I")]


@st.composite
def damaged(draw: st.DrawFn) -> bytes:
    data = bytearray(ilc.encode(draw(images())))
    # Hypothesis favours small numbers: pick the region first, so that damage reaches
    # the code, the tables and the debug section as often as the header.
    header = ilc.read_header(bytes(data))
    start = draw(st.sampled_from([0, header.code_start, header.handler_start,
                                  header.debug_start]))
    position = draw(st.integers(min(start, len(data) - 1), len(data) - 1))
    kind = draw(st.sampled_from(["flip", "overwrite", "truncate", "insert", "header"]))
    if kind == "flip":
        data[position] ^= 1 << draw(st.integers(0, 7))
    elif kind == "overwrite":
        data[position] = draw(st.integers(0, 255))
    elif kind == "truncate":
        del data[position:]
    elif kind == "insert":
        data[position:position] = draw(st.binary(min_size=1, max_size=8))
    else:
        offset, fmt = draw(st.sampled_from(HEADER_FIELDS))
        limit = 1 << 8 * struct.calcsize(fmt)
        struct.pack_into(fmt, data, offset, draw(st.integers(0, limit - 1) | st.integers(0, 40)))
    # Fixing the CRC lets the damage reach the checks behind it.
    return with_crc(data) if len(data) >= 12 and draw(st.booleans()) else bytes(data)
