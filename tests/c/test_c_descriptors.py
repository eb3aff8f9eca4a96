"""The calls' descriptors the C VM and loader read (vm/c/rl1vm.h's generated
RL1_CALL_DESCRIPTORS and RL1_PARAM_RANGES, defined in rl1vm_load.c) say
of each call what vm/language.py says of its form: its arity, whether it takes device
time (started, then polled), whether its result goes into R, the reserved variables it
writes, and each parameter's range (its low end, and the span to its high end), read from
the built library as the VM reads them.
(test_c_constants.py holds the header's block equal to what vm/isa_table.py renders;
this holds what that block means.)"""

from __future__ import annotations

import ctypes

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support.c_vm import sanitized_library

from rl1.vm import isa, isa_table
from rl1.vm.language import BUILTINS, VARIABLES, Form, Param

CALLS = isa_table.calls()
ARITY, STARTED, SETS_R, PAIRS, PAIRS_SHIFT, RESULT, FIRST_SHIFT = 0x03, 0x04, 0x08, 0x30, 4, 0xC0, 8


class Range(ctypes.Structure):
    """rl1vm.h's rl1_param_range."""
    _fields_ = (("low", ctypes.c_int16), ("span", ctypes.c_uint16))


@pytest.fixture(scope="module")
def lib(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    library = ctypes.CDLL(str(sanitized_library(tmp_path_factory)))
    library.rl1_arg_in_range.argtypes = [ctypes.c_uint8, ctypes.c_uint8, ctypes.c_int16]
    library.rl1_arg_in_range.restype = ctypes.c_bool
    return library


def descriptors(lib: ctypes.CDLL) -> list[int]:
    """Each call's u16 descriptor: its bits, and in its high byte where its parameters'
    ranges or its written variables start."""
    return list((ctypes.c_uint16 * len(CALLS)).in_dll(lib, "rl1_call_descriptors"))


def test_each_descriptor_says_what_the_language_says_of_its_call(lib: ctypes.CDLL) -> None:
    for info, descriptor in zip(CALLS, descriptors(lib), strict=True):
        form = _form(info)
        assert info.builtin is not None
        first = descriptor >> FIRST_SHIFT
        pairs = (descriptor & PAIRS) >> PAIRS_SHIFT
        written = [VARIABLES[first + k] for k in range(2 * pairs)]
        assert (descriptor & ARITY, bool(descriptor & STARTED), bool(descriptor & SETS_R),
                tuple(written)) == (info.arity, BUILTINS[info.builtin[0]].waits,
                                    form.returns_value, form.writes), info.name


def _parameters() -> list[tuple[str, int, int, Param]]:
    """Each parameter of each call: the call's name and opcode, its place, the parameter."""
    return [(info.name, info.opcode, index, param) for info in CALLS
            for index, param in enumerate(_form(info).params)]


def _form(info: isa.OpInfo) -> Form:
    form = info.form
    assert form is not None
    return form


@given(st.sampled_from(_parameters()), st.integers(-32768, 32767))
def test_an_argument_is_in_range_exactly_when_its_parameter_allows_it(
        lib: ctypes.CDLL, parameter: tuple[str, int, int, Param], value: int) -> None:
    name, opcode, index, param = parameter
    assert lib.rl1_arg_in_range(opcode, index, value) == (param.low <= value <= param.high), \
        (name, param.name, value)


def test_every_parameter_bound_and_its_neighbours(lib: ctypes.CDLL) -> None:
    for name, opcode, index, param in _parameters():
        for value in (param.low - 1, param.low, param.high, param.high + 1):
            if -32768 <= value <= 32767:
                assert lib.rl1_arg_in_range(opcode, index, value) == \
                    (param.low <= value <= param.high), (name, param.name, value)


def test_each_parameter_s_range_is_its_low_end_and_span(lib: ctypes.CDLL) -> None:
    """The ranges' table holds, from the index of each call's first parameter (its
    descriptor's high byte), its parameters' low ends and spans (high - low) in their
    order."""
    ranges = (Range * len(_parameters())).in_dll(lib, "rl1_param_ranges")
    for info, descriptor in zip(CALLS, descriptors(lib), strict=True):
        for index, param in enumerate(_form(info).params):
            entry = ranges[(descriptor >> FIRST_SHIFT) + index]
            assert (entry.low, entry.span) == (param.low, param.high - param.low), \
                (info.name, param.name)


def test_a_reading_of_two_pairs_also_sets_r_and_has_no_range(lib: ctypes.CDLL) -> None:
    """rl1vm.c's take_reading takes a reading of two pairs (IMG's) on a path of its own that
    writes the four variables and R and checks no range: so every call whose reading has
    two pairs must set R and leave its result unchecked, and one call at least has such a
    reading (else the path is dead)."""
    two_pairs = [(info.name, descriptor) for info, descriptor
                 in zip(CALLS, descriptors(lib), strict=True)
                 if (descriptor & PAIRS) >> PAIRS_SHIFT == 2]
    assert two_pairs
    for name, descriptor in two_pairs:
        assert descriptor & SETS_R and not descriptor & RESULT, name
