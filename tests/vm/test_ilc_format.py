"""The .ilc container (vm/ilc.py): the layout to the byte, round trips, the versioning
rules, and every refusal of `decode` with the file offset it points at."""

from __future__ import annotations

import dataclasses
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.ilc import images, with_crc

from rl1.vm import ilc, isa
from rl1.vm.language import Feature

LDI_5_END = bytes([0x02, 0x05, 0x00, 0x00])  # LDI 5; END
SAMPLE_DEBUG = ilc.DebugInfo("a.rob", ((0, 2), (3, 130)))
SAMPLE = ilc.Image(LDI_5_END, {97: 3}, frozenset({Feature.MOTION, Feature.IO}), SAMPLE_DEBUG)
DIGEST = ilc.source_digest("A=5\n")
DIGESTED = dataclasses.replace(
    SAMPLE, debug=dataclasses.replace(SAMPLE_DEBUG, source_digest=DIGEST))


def patched(data: bytes, offset: int, fmt: str, value: int) -> bytes:
    out = bytearray(data)
    struct.pack_into(fmt, out, offset, value)
    return with_crc(out)


def refusal(data: bytes) -> ilc.IlcFormatError:
    with pytest.raises(ilc.IlcFormatError) as caught:
        ilc.decode(data)
    return caught.value


def test_layout_to_the_byte() -> None:
    header = (b"RLIC" + bytes([1, 0]) + struct.pack("<H", 0) + bytes(4)
              + struct.pack("<HHHHI", 24, 4, 8, 2, 13))
    handlers = struct.pack("<4H", 0xFFFF, 3, 0xFFFF, 0xFFFF)
    features = struct.pack("<H", 1 << Feature.MOTION.value | 1 << Feature.IO.value)
    # name length, name, entry count; entries as (offset delta, line delta) LEB128
    # pairs: (0, 2), then (3, 128) where 128 takes two bytes.
    debug = bytes([5]) + b"a.rob" + struct.pack("<H", 2) + bytes([0, 2, 3, 0x80, 0x01])
    assert ilc.encode(SAMPLE) == with_crc(header + LDI_5_END + handlers + features + debug)


@settings(max_examples=100, deadline=None)
@given(images())
def test_decode_inverts_encode(image: ilc.Image) -> None:
    data = ilc.encode(image)
    assert ilc.decode(data) == image
    stripped = ilc.decode(ilc.encode(ilc.strip_debug(image)))
    assert stripped == ilc.Image(image.code, image.handlers, image.features, None, image.flags)


def test_a_decoded_debug_section_cannot_be_changed() -> None:
    # The verifier checks the line map it was given: it must stay the one it checked.
    debug = ilc.decode(ilc.encode(SAMPLE)).debug
    assert debug == SAMPLE_DEBUG
    with pytest.raises(dataclasses.FrozenInstanceError):
        debug.lines = ((1, 1),)  # type: ignore[misc]


def test_strip_debug_leaves_an_empty_debug_section() -> None:
    data = ilc.encode(ilc.strip_debug(SAMPLE))
    assert ilc.read_header(data).debug_size == 0
    assert len(data) == 24 + len(LDI_5_END) + 8 + 2


def test_line_at_takes_the_entry_at_or_before_an_offset() -> None:
    debug = ilc.DebugInfo("x", ((0, 2), (3, 5)))
    assert [debug.line_at(offset) for offset in (0, 2, 3, 9)] == [2, 2, 5, 5]
    assert ilc.DebugInfo("x", ((4, 1),)).line_at(0) is None


# --- versioning ----------------------------------------------------------------------

def test_a_newer_minor_version_is_read_ignoring_what_it_adds() -> None:
    data = ilc.encode(DIGESTED)
    header_end = 24
    # A 1.2 file: two more header bytes, and 3 bytes of a new section after the last.
    grown = bytearray(data[:header_end] + b"\xAA\xBB" + data[header_end:] + b"new")
    grown[5] = ilc.VERSION_MINOR + 1
    struct.pack_into("<H", grown, 12, header_end + 2)
    assert ilc.decode(with_crc(grown)) == DIGESTED


def test_a_source_digest_makes_a_1_1_file_and_follows_the_debug_section() -> None:
    plain, digested = ilc.encode(SAMPLE), ilc.encode(DIGESTED)
    assert (plain[5], digested[5]) == (0, 1)
    assert digested[24:] == plain[24:] + DIGEST
    assert ilc.decode(digested) == DIGESTED
    assert ilc.read_header(digested).end == len(digested)


def test_a_1_1_file_cut_in_its_digest_is_refused() -> None:
    data = ilc.encode(DIGESTED)
    error = refusal(with_crc(bytearray(data[:-1])))
    assert "truncated" in error.message


def test_a_1_1_file_without_debug_has_no_digest() -> None:
    data = patched(ilc.encode(ilc.strip_debug(SAMPLE)), 5, "<B", 1)
    assert ilc.decode(data) == ilc.strip_debug(SAMPLE)


def test_the_digest_tells_edited_text_and_ignores_the_encoding() -> None:
    assert ilc.source_digest("A=1\n") != ilc.source_digest("A=1 \n")
    assert len(ilc.source_digest("")) == ilc.DIGEST_SIZE


def test_the_same_minor_version_with_extra_bytes_is_refused() -> None:
    data = ilc.encode(SAMPLE)
    error = refusal(with_crc(data + b"x"))
    assert error.offset == len(data)
    assert error.message == "1 unexpected bytes after the last section"


@settings(max_examples=50, deadline=None)
@given(st.binary(min_size=1, max_size=40))
def test_extra_bytes_are_counted_from_the_last_sections_end(extra: bytes) -> None:
    data = ilc.encode(SAMPLE)
    error = refusal(with_crc(data + extra))
    assert (error.offset, error.refusal) == (len(data), ilc.Refusal.EXTRA_BYTES)
    assert error.message == f"{len(extra)} unexpected bytes after the last section"


@pytest.mark.parametrize("extra", [2, 3, 10])
def test_extra_bytes_are_counted(extra: int) -> None:
    # past a 38-byte file: 40 ^ 38 is 14, 41 ^ 38 is 15, 48 ^ 38 is 22; 40 - 38 is 2
    data = ilc.encode(dataclasses.replace(SAMPLE, debug=None))
    assert len(data) == 38
    error = refusal(with_crc(data + bytes(extra)))
    assert error.message == f"{extra} unexpected bytes after the last section"


@pytest.mark.parametrize("major", [0, 2, 255])
def test_a_major_version_other_than_1_is_refused(major: int) -> None:
    error = refusal(patched(ilc.encode(SAMPLE), 4, "<B", major))
    assert (error.offset, error.refusal) == (4, ilc.Refusal.BAD_MAJOR)
    assert f"version {major}.0 is not supported" in error.message


def test_an_unknown_required_flag_is_refused_an_optional_one_kept() -> None:
    data = ilc.encode(SAMPLE)
    error = refusal(patched(data, 6, "<H", 0x0004))
    assert (error.offset, "required flag" in error.message) == (6, True)
    flagged = patched(data, 6, "<H", 0x0100)
    assert ilc.decode(flagged) == dataclasses.replace(SAMPLE, flags=0x0100)
    assert ilc.encode(ilc.decode(flagged)) == flagged


# --- refusals ------------------------------------------------------------------------

def test_a_short_file_is_refused_as_truncated() -> None:
    data = ilc.encode(SAMPLE)
    for size in (0, 3, 10, 23):
        error = refusal(data[:size])
        assert error.offset == size
        assert "truncated" in error.message


def test_a_header_without_its_sections_is_refused_as_truncated_where_they_end() -> None:
    data = ilc.encode(SAMPLE)
    error = refusal(data[:24])  # the whole header, which the shortest file passes
    assert (error.offset, error.refusal) == (24, ilc.Refusal.TRUNCATED)
    assert error.message == (f"truncated: the header's section sizes add up to {len(data)} "
                             "bytes, the file has 24")


def test_a_source_name_keeps_every_character_but_the_surrogates() -> None:
    # A name that is not UTF-8 holds each of its bytes as a surrogate, U+D800..U+DFFF.
    name = "a\ud7ff\ud800\udc80\udfff\ue000.rob"
    assert ilc.debug_source_name(name) == "a\ud7ff\ufffd\ufffd\ufffd\ue000.rob"


def test_bad_magic_is_refused_at_offset_0() -> None:
    error = refusal(b"RLIX" + ilc.encode(SAMPLE)[4:])
    assert error.offset == 0
    assert "not an .ilc file" in error.message


def test_a_damaged_byte_is_caught_by_the_crc() -> None:
    data = bytearray(ilc.encode(SAMPLE))
    data[24] ^= 0x40
    error = refusal(bytes(data))
    assert error.offset == 8
    assert "CRC-32 mismatch" in error.message


@pytest.mark.parametrize(("field", "value", "message"), [
    (12, 23, "header size 23"),
    (12, 26, "header size 26"),
    (16, 6, "handler table section must be 8"),
    (18, 4, "features section must be 2"),
])
def test_wrong_fixed_sizes_are_refused_at_their_field(field: int, value: int,
                                                      message: str) -> None:
    error = refusal(patched(ilc.encode(SAMPLE), field, "<H", value))
    assert error.offset == field
    assert message in error.message


def test_sections_running_past_the_end_are_refused_as_truncated() -> None:
    data = ilc.encode(SAMPLE)
    for fmt, field, value in (("<H", 14, 5), ("<I", 20, 14)):
        error = refusal(patched(data, field, fmt, value))
        assert error.offset == len(data)
        assert f"add up to {len(data) + 1} bytes" in error.message
    error = refusal(with_crc(data[:-1]))
    assert error.offset == len(data) - 1


def test_a_handler_outside_the_code_is_refused_at_its_entry() -> None:
    handler_97 = 24 + len(LDI_5_END) + 2
    error = refusal(patched(ilc.encode(SAMPLE), handler_97, "<H", 4))
    assert error.offset == handler_97
    assert ":97 points at code offset 4, outside the 4-byte code" in error.message


def test_an_unknown_feature_bit_is_refused() -> None:
    features = 24 + len(LDI_5_END) + 8
    error = refusal(patched(ilc.encode(SAMPLE), features, "<H", 1 << 12))
    assert error.offset == features
    assert "unknown feature bits 0x1000" in error.message


DEBUG = 24 + len(LDI_5_END) + 8 + 2  # where SAMPLE's debug section starts


def with_debug(section: bytes) -> bytes:
    """SAMPLE's file with its debug section replaced."""
    data = bytearray(ilc.encode(SAMPLE)[:DEBUG] + section)
    struct.pack_into("<I", data, 20, len(section))
    return with_crc(data)


@pytest.mark.parametrize(("section", "offset", "message"), [
    (bytes([9]) + b"a.rob", DEBUG + 1,
     "the debug section ends in the middle of a field (9 bytes needed, 5 left)"),
    (bytes([2]) + b"\xff\xfe" + bytes(2), DEBUG + 1, "not UTF-8"),
    (bytes([0, 1]), DEBUG + 1, "ends in the middle of a field (2 bytes needed, 1 left)"),
    (bytes([0, 2, 0, 0, 1, 0, 1]), DEBUG + 5, "repeats the previous entry's code offset"),
    (bytes([0, 1, 0, 0, 0]), DEBUG + 3, "line 0"),
    (bytes([0, 1, 0, 0, 0x80, 0x80, 0x04]), DEBUG + 3, "line 65536) is out of range"),
    (bytes([0, 1, 0, 0, 0x81, 0x80, 0x80, 0x00]), DEBUG + 4, "longer than 3 bytes"),
    (bytes([0, 1, 0, 0, 0x81, 0x00]), DEBUG + 4, "not in its shortest form"),
    (bytes([0, 1, 0, 0, 1, 7]), DEBUG + 5, "1 bytes left over"),
])
def test_a_malformed_debug_section_is_refused(section: bytes, offset: int,
                                              message: str) -> None:
    error = refusal(with_debug(section))
    assert error.offset == offset
    assert message in error.message


# --- the writer's limits -------------------------------------------------------------

FUSED = bytes([isa.BY_NAME["MOVV"].opcode, 0, 1])  # MOVV, an instruction of 1.2


@pytest.mark.parametrize(("image", "message"), [
    (ilc.Image(bytes(0x10000), {}, frozenset()),
     "code is 65536 bytes; the format allows 65535"),
    (ilc.Image(LDI_5_END, {95: 0}, frozenset()), "handler labels must be 96..99, not [95]"),
    (ilc.Image(LDI_5_END, {96: 4}, frozenset()), "handler :96 at 4 is outside the code"),
    (ilc.Image(LDI_5_END, {}, frozenset(), ilc.DebugInfo("x" * 256, ())),
     "source name is 256 bytes; the format allows 255"),
    (ilc.Image(LDI_5_END, {}, frozenset(), ilc.DebugInfo("x", ((0, 5), (3, 4)))),
     "line entry (3, 4): lines must not decrease"),
    (ilc.Image(LDI_5_END, {}, frozenset(), ilc.DebugInfo("x", ((3, 5), (3, 6)))),
     "line entry (3, 6): offsets must increase"),
    (ilc.Image(LDI_5_END, {}, frozenset(), ilc.DebugInfo("x", ((0, 0),))),
     "line entry (0, 0): offsets are u16, lines 1..65535"),
    (ilc.Image(LDI_5_END, {}, frozenset(), ilc.DebugInfo("x", ((-1, 1),))),
     "line entry (-1, 1): offsets are u16, lines 1..65535"),
    # Past 1.0 (here for its code, not a digest) a debug section needs the digest after it.
    (ilc.Image(FUSED, {}, frozenset(), ilc.DebugInfo("x", ((0, 1),))),
     "a version 1.2 file's debug section is followed by the source digest, and this image "
     "has none"),
])
def test_encode_refuses_an_image_the_format_cannot_hold(image: ilc.Image,
                                                        message: str) -> None:
    with pytest.raises(ValueError) as caught:
        ilc.encode(image)
    assert str(caught.value) == message


def test_the_last_line_and_code_offset_are_written_and_read() -> None:
    # The container holds any u16 offset; that it starts an instruction is the verifier's.
    lines = ((0, ilc.MAX_LINE), (ilc.MAX_CODE_SIZE, ilc.MAX_LINE))
    image = ilc.Image(LDI_5_END, {}, frozenset(), ilc.DebugInfo("x", lines))
    assert ilc.decode(ilc.encode(image)) == image


def test_as_many_line_entries_as_the_count_holds_are_written_and_read() -> None:
    lines = tuple((offset, 1) for offset in range(ilc.MAX_LINE_ENTRIES))
    image = ilc.Image(LDI_5_END, {}, frozenset(), ilc.DebugInfo("x", lines))
    assert ilc.decode(ilc.encode(image)) == image
    with pytest.raises(ValueError) as caught:
        ilc.encode(dataclasses.replace(
            image, debug=ilc.DebugInfo("x", (*lines, (ilc.MAX_CODE_SIZE, 1)))))
    assert str(caught.value) == "65536 line entries; the format allows 65535"


def test_a_source_name_of_the_longest_length_is_written_and_read() -> None:
    name = "\u00e9" * 127 + "x"  # 255 bytes of UTF-8
    image = ilc.Image(LDI_5_END, {}, frozenset(), ilc.DebugInfo(name, ()))
    assert ilc.decode(ilc.encode(image)) == image
