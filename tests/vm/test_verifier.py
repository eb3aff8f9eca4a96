"""The verifier (vm/verifier.py): what it accepts, every refusal with the file offset it
points at, and that no damage to a valid file makes it fail in any other way."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.ilc import damaged, images, with_crc

from rl1.vm import ilc, isa, machine
from rl1.vm.ilc import Refusal
from rl1.vm.language import BUILTINS, Feature
from rl1.vm.scripted import LossAt, LossDuring, Script, ScriptedDevice
from rl1.vm.verifier import VerifiedProgram, VerifyError, verify

CODE = 24  # file offset of the code section (the 1.0 header's size)
ALL_FEATURES = frozenset(Feature)


def op(name: str, *operands: int, args: tuple[isa.Arg, ...] = ()) -> bytes:
    return isa.encode(isa.BY_NAME[name], operands, args)


def const(value: int) -> isa.Arg:
    return isa.Arg(False, value)


def var(index: int) -> isa.Arg:
    return isa.Arg(True, index)


def file_of(code: bytes, handlers: dict[int, int] | None = None,
            features: frozenset[Feature] = ALL_FEATURES,
            debug: ilc.DebugInfo | None = None) -> bytes:
    return ilc.encode(ilc.Image(code, handlers or {}, features, debug))


def refusal(data: bytes) -> VerifyError:
    with pytest.raises(VerifyError) as caught:
        verify(data)
    return caught.value


def test_a_valid_file_gives_its_instructions_and_their_index() -> None:
    code = op("LDI", 5) + op("STV", 0) + op("MOV", args=(var(0), const(-3))) + op("JMP", 3)
    program = verify(file_of(code, {96: 5}))
    assert [i.info.name for i in program.instructions] == ["LDI", "STV", "MOV", "JMP"]
    assert program.index_of == {0: 0, 3: 1, 5: 2, 11: 3}
    assert program.instructions[2].args == (var(0), const(-3))
    assert program.image.handlers == {96: 5}


def test_a_verified_program_cannot_be_pointed_at_other_code() -> None:
    # The VM checks nothing the verifier checked: what it was given stays what passed.
    program = verify(file_of(op("LDI", 5)))
    unverified = isa.decode_at(op("JMP", 9), 0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        program.instructions = (unverified,)  # type: ignore[misc]
    assert program.instructions == (isa.decode_at(op("LDI", 5), 0),)


@settings(max_examples=100, deadline=None)
@given(images())
def test_every_valid_image_verifies_and_decodes_to_its_own_code(image: ilc.Image) -> None:
    program = verify(ilc.encode(image))
    assert program.image == image
    reencoded = b"".join(isa.encode(i.info, i.operands, i.args)
                         for i in program.instructions)
    assert reencoded == image.code
    assert [program.index_of[i.offset] for i in program.instructions] == list(
        range(len(program.instructions)))


def test_falling_off_the_end_is_allowed() -> None:
    verify(file_of(op("LDI", 1)))
    assert verify(file_of(b"")).instructions == ()


def test_container_refusals_come_as_verify_errors() -> None:
    error = refusal(b"RLIX" + file_of(op("END"))[4:])
    assert isinstance(error, ilc.IlcFormatError)
    assert error.offset == 0


@pytest.mark.parametrize(("code", "offset", "message", "kind"), [
    (op("LDI", 0) + bytes([0x0B]), CODE + 3, "code offset 3: unknown opcode 0x0B",
     Refusal.UNKNOWN_OPCODE),
    (op("LDI", 0)[:2], CODE, "LDI needs 3 bytes, only 2 remain", Refusal.CUT_OFF),
    (op("LDI", 0) + op("MVI", args=(const(1), const(1), const(1)))[:5], CODE + 3,
     "MVI needs 8 bytes, only 5 remain", Refusal.CUT_OFF),
    (op("JMP", 3), CODE + 1, "jump target 3 is outside the 3-byte code", Refusal.BAD_JUMP),
    (op("JMP", 0xFFFF), CODE + 1, "jump target 65535 is outside", Refusal.BAD_JUMP),
    (op("LDI", 0) + op("JGT", 0, 1), CODE + 5, "target 1 is in the middle of the "
                                               "instruction at 0", Refusal.BAD_JUMP),
    (op("LDV", 53), CODE + 1, "LDV: variable index 53 is out of range 0..52", Refusal.BAD_VARIABLE),
    (op("LDI", 0) + op("JZ", 255, 0), CODE + 4, "JZ: variable index 255", Refusal.BAD_VARIABLE),
    (op("MOV", args=(const(0), var(53))), CODE + 4, "MOV argument r: variable index 53",
     Refusal.BAD_VARIABLE),
    (op("MOV", args=(const(0), var(0x100))), CODE + 4, "variable index 256", Refusal.BAD_VARIABLE),
    (op("MOV", args=(const(13), const(0))), CODE + 2, "MOV argument l = 13 is out of "
                                                      "range -12..12", Refusal.ARGUMENT_RANGE),
    (bytes([isa.BY_NAME["MOV"].opcode, 0x04, 0, 0, 0, 0]), CODE + 1,
     "argument mask 0x04 marks arguments beyond its 2", Refusal.BAD_MASK),
])
def test_bad_code_is_refused_at_the_offending_byte(code: bytes, offset: int, message: str,
                                                   kind: Refusal) -> None:
    error = refusal(file_of(code))
    assert (error.offset, error.refusal) == (offset, kind)
    assert message in error.message


# Whole instructions of each length (1, 2, 3 and 6 bytes) to put anything after.
WHOLE = [op("END"), op("STV", 0), op("LDI", -2), op("MOV", args=(var(0), const(-3)))]
UNKNOWN_OPCODE = 0x0B


@pytest.mark.parametrize("before", [4, 8, 9, 40])
def test_a_refusal_points_at_code_start_plus_its_code_offset(before: int) -> None:
    # 24 + 8 is 32, not 24 | 8: a refusal past code offset 7 says where it is too.
    error = refusal(file_of(op("END") * before + bytes([UNKNOWN_OPCODE])))
    assert (error.offset, error.refusal) == (CODE + before, Refusal.UNKNOWN_OPCODE)
    assert error.message.startswith(f"code offset {before}: unknown opcode 0x0B")


@settings(max_examples=100, deadline=None)
@given(st.lists(st.sampled_from(WHOLE), max_size=30))
def test_an_unknown_opcode_after_any_code_is_refused_at_its_byte(
    prefix: list[bytes],
) -> None:
    at = len(b"".join(prefix))
    error = refusal(file_of(b"".join(prefix) + bytes([UNKNOWN_OPCODE])))
    assert (error.offset, error.refusal) == (CODE + at, Refusal.UNKNOWN_OPCODE)
    assert error.message.startswith(f"code offset {at}: unknown opcode 0x0B")


def test_an_instruction_cut_off_after_another_is_refused() -> None:
    # At code offset 3, 3 bytes of LDI with 2 left: 3 + 3 > 5, though 3 | 3 is not.
    error = refusal(file_of(op("LDI", 0) + op("LDI", 0)[:2]))
    assert (error.offset, error.refusal) == (CODE + 3, Refusal.CUT_OFF)
    assert "code offset 3: LDI needs 3 bytes, only 2 remain in the code" in error.message


@settings(max_examples=100, deadline=None)
@given(st.lists(st.sampled_from(WHOLE), max_size=30), st.sampled_from(WHOLE[1:]),
       st.data())
def test_any_code_whose_last_instruction_is_cut_off_is_refused_at_it(
    prefix: list[bytes], last: bytes, data: st.DataObject,
) -> None:
    kept = data.draw(st.integers(1, len(last) - 1), label="bytes kept")
    at = len(b"".join(prefix))
    error = refusal(file_of(b"".join(prefix) + last[:kept]))
    assert (error.offset, error.refusal) == (CODE + at, Refusal.CUT_OFF)
    name = isa.OPCODES[last[0]].name
    assert (f"code offset {at}: {name} needs {len(last)} bytes, only {kept} remain in the "
            "code") in error.message


@pytest.mark.parametrize("minor", [0, ilc.DIGEST_MINOR])
def test_an_instruction_newer_than_the_files_version_is_unknown(minor: int) -> None:
    data = bytearray(file_of(op("LDI", 0) + op("MOVV", 0, 1)))
    assert data[5] == isa.FUSED_MINOR  # the writer says what the code needs
    data[5] = minor
    error = refusal(with_crc(data))
    assert (error.offset, error.refusal) == (CODE + 3, Refusal.UNKNOWN_OPCODE)
    assert (f"code offset 3: MOVV is an instruction of format 1.{isa.FUSED_MINOR}, but the "
            f"file says 1.{minor}") in error.message


PARAMETERS = [(info, index, param) for info in isa.OPCODES.values()
              if info.form is not None for index, param in enumerate(info.form.params)]


@pytest.mark.parametrize(("info", "index", "param"), PARAMETERS,
                         ids=[f"{info.name}-{param.name}" for info, _, param in PARAMETERS])
def test_constant_arguments_are_checked_against_the_builtin_table(
    info: isa.OpInfo, index: int, param: object,
) -> None:
    assert info.form is not None
    params = info.form.params
    # what a constant argument can hold: 16 bits, or a byte in a compact call
    lowest, highest = (-0x80, 0x7F) if info.compact else (-0x8000, 0x7FFF)

    def call_with(value: int) -> bytes:
        args = tuple(const(value if i == index else max(p.low, lowest))
                     for i, p in enumerate(params))
        return file_of(isa.encode(info, (), args))

    low, high = params[index].low, params[index].high
    verify(call_with(max(low, lowest)))
    verify(call_with(min(high, highest)))
    for outside in (low - 1, high + 1):
        if lowest <= outside <= highest:  # a range as wide as the field has no outside
            error = refusal(call_with(outside))
            assert error.offset == CODE + 2 + info.arg_size * index
            assert f"= {outside} is out of range {low}..{high}" in error.message


def test_a_call_needs_its_feature_in_the_header() -> None:
    error = refusal(file_of(op("LDI", 0) + op("IMG"),
                            features=ALL_FEATURES - {Feature.VISION}))
    assert error.offset == CODE + 3
    assert "IMG needs the device feature VISION" in error.message
    assert BUILTINS["TIM"].feature is None
    verify(file_of(op("TIM", args=(const(5),)), features=frozenset()))


def test_a_handler_must_start_an_instruction() -> None:
    code = op("LDI", 0) + op("END")
    handler_98 = CODE + len(code) + 2 * 2
    error = refusal(file_of(code, {96: 3, 98: 1}))
    assert error.offset == handler_98
    assert "handler :98 at code offset 1 is in the middle of the instruction at 0" \
        in error.message


def test_a_line_entry_must_start_an_instruction() -> None:
    code = op("LDI", 0) + op("END")
    debug_start = CODE + len(code) + 8 + 2
    data = file_of(code, debug=ilc.DebugInfo("p.rob", ((0, 1), (2, 1))))
    error = refusal(data)
    # name length byte, name, count; then the entries, 2 bytes each here.
    assert error.offset == debug_start + 1 + 5 + 2 + 2
    assert "line entry for code offset 2 is in the middle of the instruction at 0" \
        in error.message
    error = refusal(file_of(code, debug=ilc.DebugInfo("p.rob", ((0, 1), (4, 1)))))
    assert "line entry for code offset 4 is outside the 4-byte code" in error.message


# --- damage of every kind ------------------------------------------------------------

# Lost lines early and often, so that runs take the handler paths too.
LOSSES = Script(losses=(LossAt(0), LossDuring("MOV", 1, 0), LossDuring("MVI", 1, 0),
                        LossAt(700)))


def runs_safely(program: VerifiedProgram) -> None:
    """The VM runs a verified program to an end or a fault, never to an exception."""
    result = machine.run(program, ScriptedDevice(LOSSES), budget=300)
    assert len(result.variables) == 53


@settings(max_examples=300, deadline=None)
@given(damaged())
def test_damage_is_refused_or_verifies_never_anything_else(data: bytes) -> None:
    try:
        program = verify(data)
    except VerifyError as error:
        assert 0 <= error.offset <= len(data)
        return
    header = ilc.read_header(data)
    debug = program.image.debug
    written_minor = max(isa.code_minor(program.image.code),
                        ilc.DIGEST_MINOR if debug and debug.source_digest else 0)
    if (header.minor, header.flags) == (written_minor, 0):
        # One image, one encoding: what verifies is exactly what the writer writes.
        assert ilc.encode(program.image) == data
    runs_safely(program)


@settings(max_examples=100, deadline=None)
@given(images())
def test_every_valid_image_runs_safely(image: ilc.Image) -> None:
    runs_safely(verify(ilc.encode(image)))
