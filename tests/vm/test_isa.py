"""The instruction table: unique opcodes, lengths known from the first byte, round trips."""

from hypothesis import given, settings
from hypothesis import strategies as st

from rl1.vm import isa
from rl1.vm.language import BUILTINS


def test_every_builtin_form_has_exactly_one_opcode() -> None:
    forms = {(b.mnemonic, form.selector) for b in BUILTINS.values() for form in b.forms}
    assert set(isa.BY_FORM) == forms
    assert len(isa.BY_NAME) == len(isa.OPCODES)


@st.composite
def instructions(draw: st.DrawFn) -> tuple[isa.OpInfo, tuple[int, ...], tuple[isa.Arg, ...]]:
    info = draw(st.sampled_from(sorted(isa.OPCODES.values(), key=lambda i: i.opcode)))
    operands: list[int] = []
    for operand in info.operands:
        if operand is isa.Operand.VAR:
            operands.append(draw(st.integers(0, 52)))
        elif operand is isa.Operand.IMM:
            operands.append(draw(st.integers(-32768, 32767)))
        elif operand is isa.Operand.BYTE:
            operands.append(draw(st.integers(-128, 127)))
        elif operand is isa.Operand.ADDR:
            operands.append(draw(st.integers(0, 65535)))
    args = tuple(
        isa.Arg(True, draw(st.integers(0, 52))) if draw(st.booleans())
        else isa.Arg(False, draw(st.integers(-128, 127) if info.compact
                                 else st.integers(-32768, 32767)))
        for _ in range(info.arity)
    )
    return info, tuple(operands), args


@settings(max_examples=300, deadline=None)
@given(instructions())
def test_encode_then_decode_is_identity(
    instruction: tuple[isa.OpInfo, tuple[int, ...], tuple[isa.Arg, ...]],
) -> None:
    info, operands, args = instruction
    data = isa.encode(info, operands, args)
    assert len(data) == info.length
    decoded = isa.decode_at(data, 0)
    assert (decoded.info, decoded.operands, decoded.args) == (info, operands, args)
