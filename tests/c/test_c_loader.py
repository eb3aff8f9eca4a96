"""The C loader and verifier (vm/c/) against the Python verifier (vm/verifier.py): the same
acceptance, the same refusal at the same file offset, and the same source line for
every code offset, on every vector file, on every opcode and parameter bound, and on
generated and damaged files. The C side checks jump targets two ways (a bitmap, and a
rescan without memory, for a bitmap too small or none); each must agree with Python.

Through ctypes, as the C VM's tests (test_c_vm.py) and `rl1c run --engine c` are: the
shared library is vm/native.py's, built with UBSan here, which aborts the run on
undefined behaviour."""

from __future__ import annotations

import ctypes
import re
import struct
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT
from support.c_vm import sanitized_library
from support.ilc import CALLS_WITH_ARGUMENTS, damaged, images, with_crc

from rl1.vm import ilc, isa
from rl1.vm.language import BUILTINS, Feature
from rl1.vm.verifier import VerifyError, verify

sys.path.insert(0, str(ROOT / "spec" / "vectors"))
from ilc_files import run_files, verifier_files

C_DIR = ROOT / "vm" / "c"
CODE = 24  # file offset of the code section in a file of version 1.0 to 1.2
MAX_BITMAP = 8192  # RL1_BITMAP_SIZE(65535)


class Loader:
    """The C loader through ctypes."""

    def __init__(self, library: Path) -> None:
        self.lib = ctypes.CDLL(str(library))
        self.lib.rl1_test_load.argtypes = [ctypes.c_char_p, ctypes.c_uint32, ctypes.c_size_t,
                                           ctypes.POINTER(ctypes.c_uint32)]
        self.lib.rl1_test_load.restype = ctypes.c_int
        self.lib.rl1_test_line_at.argtypes = [ctypes.c_char_p, ctypes.c_uint32,
                                              ctypes.c_uint16]
        self.lib.rl1_test_line_at.restype = ctypes.c_uint16

    def load(self, data: bytes, bitmap_size: int) -> tuple[int, int]:
        """(status, error offset); status 0 accepts, else an ilc.Refusal. The bitmap has
        `bitmap_size` bytes, at most MAX_BITMAP (ffi.c's); 0: none."""
        assert 0 <= bitmap_size <= MAX_BITMAP
        offset = ctypes.c_uint32(0)
        status = self.lib.rl1_test_load(data, len(data), bitmap_size, ctypes.byref(offset))
        return int(status), offset.value if status else 0

    def line_at(self, data: bytes, code_offset: int) -> int:
        return int(self.lib.rl1_test_line_at(data, len(data), code_offset))


@pytest.fixture(scope="session")
def c_loader(tmp_path_factory: pytest.TempPathFactory) -> Loader:
    return Loader(sanitized_library(tmp_path_factory))


def python_verdict(data: bytes) -> tuple[int, int]:
    try:
        verify(data)
    except VerifyError as error:
        return int(error.refusal), error.offset
    return 0, 0


def assert_agree(c_loader: Loader, data: bytes) -> tuple[int, int]:
    expected = python_verdict(data)
    # The bitmap the header's code size needs (RL1_BITMAP_SIZE), more, less, and none.
    needed = (struct.unpack_from("<H", data, 14)[0] + 7) // 8 if len(data) >= 16 else 0
    for size in {MAX_BITMAP, needed, max(needed - 1, 0), 0}:
        assert c_loader.load(data, size) == expected, size
    return expected


def assert_lines_agree(c_loader: Loader, data: bytes) -> None:
    debug = ilc.decode(data).debug
    code_size = ilc.read_header(data).code_size
    for offset in range(min(code_size + 2, 0x10000)):
        expected = debug.line_at(offset) if debug is not None else None
        assert c_loader.line_at(data, offset) == (expected or 0), offset


def test_the_status_codes_are_the_python_refusals() -> None:
    header = (C_DIR / "rl1vm.h").read_text(encoding="utf-8")
    refusals = header[header.index("typedef enum rl1_refusal {"):header.index("} rl1_refusal;")]
    codes = {name: int(value) for name, value in re.findall(r"RL1_(\w+) = (\d+)", refusals)}
    assert codes == {"ACCEPTED": 0} | {refusal.name: refusal.value for refusal in ilc.Refusal}


def test_every_vector_file_is_accepted_with_its_lines(c_loader: Loader) -> None:
    files = [data for _, data in run_files()]
    assert len(files) > 200
    for data in files:
        assert assert_agree(c_loader, data) == (0, 0)
        assert_lines_agree(c_loader, data)


def test_the_verifier_files_get_the_python_verdicts(c_loader: Loader) -> None:
    files = list(verifier_files())
    assert len(files) > 50
    for _, data in files:
        assert_agree(c_loader, data)


def file_of(code: bytes, features: frozenset[Feature] = frozenset(Feature)) -> bytes:
    return ilc.encode(ilc.Image(code, {}, features))


@pytest.mark.parametrize("opcode", range(256))
def test_every_opcode_whole_cut_and_in_every_position(c_loader: Loader, opcode: int) -> None:
    # Zero operands are valid for every instruction (variable A, constant 0, target 0)
    # except where 0 is out of a parameter's range (TIM): that refusal must agree too.
    for code in (bytes([opcode]) + bytes(7), bytes([opcode]), bytes([0x00, opcode]),
                 bytes([opcode]) + bytes(7) + bytes([opcode])):
        assert_agree(c_loader, file_of(code))
        assert_agree(c_loader, file_of(code, frozenset()))




@pytest.mark.parametrize("info", CALLS_WITH_ARGUMENTS,
                         ids=[info.name for info in CALLS_WITH_ARGUMENTS])
def test_every_parameter_bound_and_mask(c_loader: Loader, info: isa.OpInfo) -> None:
    assert info.form is not None
    params = info.form.params
    # a field's values: 16 bits, or a byte in a compact call
    low_end, high_end = (-0x80, 0x7F) if info.compact else (-0x8000, 0x7FFF)
    lows = [max(p.low, low_end) for p in params]
    for index, param in enumerate(params):
        for value in (param.low - 1, param.low, param.high, param.high + 1):
            if not low_end <= value <= high_end:
                continue
            args = tuple(isa.Arg(False, value if i == index else low)
                         for i, low in enumerate(lows))
            assert_agree(c_loader, file_of(isa.encode(info, (), args)))
        for variable in (52, 53, 0xFF if info.compact else 0xFFFF):
            args = tuple(isa.Arg(i == index, variable if i == index else low)
                         for i, low in enumerate(lows))
            assert_agree(c_loader, file_of(isa.encode(info, (), args)))
    lowest = isa.encode(info, (), tuple(isa.Arg(False, low) for low in lows))
    for mask in range(256):
        assert_agree(c_loader, file_of(lowest[:1] + bytes([mask]) + lowest[2:]))
    feature = BUILTINS[info.builtin[0]].feature if info.builtin else None
    if feature is not None:
        assert assert_agree(c_loader, file_of(lowest, frozenset(Feature) - {feature})) == (
            ilc.Refusal.MISSING_FEATURE, CODE)


def test_section_sizes_whose_sum_passes_32_bits_are_truncated(c_loader: Loader) -> None:
    data = bytearray(ilc.encode(ilc.Image(bytes([0x30, 0, 0]), {}, frozenset(),
                                          ilc.DebugInfo("p", ((0, 1),)))))
    # header 24 + code 3 + 10 + debug: a u32 sum wraps to a size below the file's.
    struct.pack_into("<I", data, 20, 0xFFFFFFFF - 24 - 3 - 10 + 20)
    assert assert_agree(c_loader, with_crc(data)) == (ilc.Refusal.TRUNCATED, len(data))
    struct.pack_into("<HH", data, 12, 0xFFFF, 0xFFFF)  # and a newer minor's header size
    data[5] = ilc.VERSION_MINOR + 1
    assert assert_agree(c_loader, with_crc(data)) == (ilc.Refusal.TRUNCATED, len(data))


# The bytes where UTF-8's rules change (Unicode's table 3-7), and any byte.
UTF8_EDGES = [0x00, 0x7F, 0x80, 0x8F, 0x90, 0x9F, 0xA0, 0xBF, 0xC0, 0xC1, 0xC2, 0xDF, 0xE0,
              0xE1, 0xEC, 0xED, 0xEE, 0xEF, 0xF0, 0xF1, 0xF3, 0xF4, 0xF5, 0xFF]


@settings(max_examples=1000, deadline=None)
@given(st.lists(st.sampled_from(UTF8_EDGES) | st.integers(0, 255), max_size=8).map(bytes))
def test_any_source_name_bytes_are_judged_alike(c_loader: Loader, name: bytes) -> None:
    # Strict UTF-8 both sides: overlong forms, surrogates, past U+10FFFF, cut sequences.
    data = bytearray(ilc.encode(ilc.Image(b"", {}, frozenset(), ilc.DebugInfo("", ()))))
    data[CODE + 10:CODE + 11] = bytes([len(name)]) + name
    struct.pack_into("<I", data, 20, 3 + len(name))
    assert_agree(c_loader, with_crc(data))


@settings(max_examples=200, deadline=None)
@given(images())
def test_generated_images_are_accepted_with_the_same_lines(c_loader: Loader,
                                                           image: ilc.Image) -> None:
    data = ilc.encode(image)
    assert assert_agree(c_loader, data) == (0, 0)
    assert_lines_agree(c_loader, data)


@settings(max_examples=1000, deadline=None)
@given(damaged())
def test_damaged_files_get_the_same_verdict(c_loader: Loader, data: bytes) -> None:
    assert_agree(c_loader, data)


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=64).map(lambda tail: b"RLIC\x01" + tail), st.booleans())
def test_arbitrary_bytes_after_the_magic_get_the_same_verdict(
    c_loader: Loader, data: bytes, fix_crc: bool,
) -> None:
    assert_agree(c_loader, with_crc(data) if fix_crc and len(data) >= 12 else data)
