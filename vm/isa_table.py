"""The instruction table of spec/ilc.md, and the C VM's opcode and feature constants,
rendered from isa.OPCODES and language.Feature.

`python -m rl1.vm.isa_table` prints the table; tests/project/test_ilc_spec.py checks that
the spec holds exactly it, so the document cannot drift from the code. `python -m
rl1.vm.isa_table --c` prints the constants' block of vm/c/rl1vm.h (the opcodes, the
features, and each call's descriptor: what the VM's call path and the verifier need to
know of it), which tests/c/test_c_constants.py holds equal to the header's.
"""

from __future__ import annotations

import sys

from . import isa
from .language import BUILTINS, VARIABLES, Feature, Form

HEADER = ("| opcode | mnemonic | operands | bytes | meaning | writes | serves |\n"
          "|---|---|---|---|---|---|---|")

_OPERAND_TEXT = {isa.Operand.VAR: "v", isa.Operand.IMM: "i", isa.Operand.ADDR: "a",
                 isa.Operand.BYTE: "b"}

# What source construct each non-call instruction compiles from (spec/language.md).
_SERVES = {
    "END": "`(END)`",
    "LDV": "`V=` with a variable first", "LDI": "`V=` with a constant first",
    "LDR": "`V=` with a call first", "STV": "`V=` (the store)",
    "INC": "`V++`", "DEC": "`V--`",
    "JMP": "`#NN`", "JZ": "`?V=#NN`", "JGT": "`?V>#NN`", "JLT": "`?V<#NN`",
}
_FUSED = f"(-O2; format 1.{isa.FUSED_MINOR})"
_SERVES |= {
    "MOVV": f"`V=W` {_FUSED}", "MOVI": f"`V=i` {_FUSED}", "MOVR": f"`V=(call)` {_FUSED}",
    "MOVB": f"`V=i`, i in -128..127 {_FUSED}",
    "DJGT": f"`V--; ?V>#NN` {_FUSED}", "SJZ": f"`V=...; ?V=#NN` {_FUSED}",
    "SJGT": f"`V=...; ?V>#NN` {_FUSED}", "SJLT": f"`V=...; ?V<#NN` {_FUSED}",
}
_ALU_SERVES = {isa.ALU_VAR: "a variable", isa.ALU_IMM: "a constant", isa.ALU_RESULT: "a call"}
# The load-and-operate blocks: the first two operands of an expression.
_COMPUTE_SERVES = {
    isa.COMPUTE_VAR_VAR: "a variable and a variable",
    isa.COMPUTE_VAR_IMM: "a variable and a constant",
    isa.COMPUTE_RESULT_VAR: "a call and a variable",
    isa.COMPUTE_RESULT_IMM: "a call and a constant",
}


def operands(info: isa.OpInfo) -> str:
    if isa.Operand.ARGS in info.operands:
        form = info.form
        assert form is not None
        names = ", ".join(param.name for param in form.params)
        return f"mask, {names}" + (" (a byte each)" if info.compact else "")
    return ", ".join(_OPERAND_TEXT[operand] for operand in info.operands) or "—"


def serves(info: isa.OpInfo) -> str:
    if info.builtin is not None and info.name != "END":
        mnemonic, selector = info.builtin
        form = info.form
        assert form is not None
        words = " ".join(filter(None, [mnemonic, selector,
                                       ",".join(param.name for param in form.params)]))
        if info.compact:
            return (f"`({words})`, constants in -128..127 "
                    f"(-O2; format 1.{isa.COMPACT_MINOR})")
        return f"`({words})`"
    if info.name in _SERVES:
        return _SERVES[info.name]
    base = info.opcode & ~7
    operator = isa.ALU_OPERATORS[info.opcode - base]
    if base in _COMPUTE_SERVES:
        return f"`{operator}` between {_COMPUTE_SERVES[base]}, first in `V=` {_FUSED}"
    return f"`{operator}` then {_ALU_SERVES[base]}"


def writes(info: isa.OpInfo) -> str:
    """The reserved variables a call sets (spec/language.md, section 8)."""
    form = info.form
    return ", ".join(form.writes) if form is not None and form.writes else "—"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")  # GitHub's tables split on | even in code spans


def row(info: isa.OpInfo) -> str:
    return (f"| 0x{info.opcode:02X} | {info.name} | {operands(info)} | {info.length} "
            f"| {_cell(info.meaning)} | {writes(info)} | {_cell(serves(info))} |")


def render() -> str:
    rows = [row(info) for info in sorted(isa.OPCODES.values(), key=lambda i: i.opcode)]
    return "\n".join([HEADER, *rows])


# The lines that open and close the generated block in vm/c/rl1vm.h.
C_BEGIN = "/* ---- Generated from vm/isa.py by `python -m rl1.vm.isa_table --c`: do not edit */"
C_END = "/* ---- End of the generated constants ---- */"


# The int16 range a result or an argument has when the language sets none.
_ANY = (-32768, 32767)


def calls() -> list[isa.OpInfo]:
    """The built-in calls, in opcode order from isa.CALL_BASE."""
    return sorted((info for info in isa.OPCODES.values() if info.opcode >= isa.CALL_BASE
                   and info.builtin is not None and not info.compact),
                  key=lambda info: info.opcode)


def _form(info: isa.OpInfo) -> Form:
    form = info.form
    assert form is not None
    return form


def _kinds(values: list[tuple[int, ...]], empty: tuple[int, ...]) -> list[tuple[int, ...]]:
    """The distinct values other than `empty`, in the order of their first call: kind n
    is the n-th of them (0 is `empty`); two bits of a descriptor hold the kind."""
    kinds = list(dict.fromkeys(value for value in values if value != empty))
    assert len(kinds) <= 3, "two bits of a call's descriptor hold the kind"
    return kinds


def _select(kinds: list[int], name: str) -> str:
    """A C expression of `kind` (1, 2, ...) that gives kinds[kind - 1]."""
    expression = f"{kinds[-1]}"
    for index in range(len(kinds) - 2, -1, -1):
        expression = f"({name}) == {index + 1}u ? {kinds[index]} : {expression}"
    return f"({expression})"


def _c_int(value: int) -> str:
    """A C constant of type int on every target (32768 is a long where int is 16 bits)."""
    return {-32768: "INT16_MIN", 32767: "INT16_MAX"}.get(value, str(value))


def _initializer(items: list[str]) -> list[str]:
    """A C initializer of `items` over lines of at most 88 characters, each line but the
    last ending in a backslash (the initializer is a macro's body)."""
    lines, line = [], "    {"
    for index, item in enumerate(items):
        text = item + ("}" if index == len(items) - 1 else ", ")
        if len(line) + len(text) > 85:
            lines.append(line.rstrip() + " \\")
            line = "     "
        line += text
    return [*lines, line]


def render_descriptors() -> list[str]:
    """Each call's descriptor, from vm/language.py (spec/ilc.md 8.3 and 12): a byte of
    bits, and above it a byte that says where its parameters' ranges start in one list
    of ranges, or which reserved variables it writes: one load of a u16 gives both."""
    infos = calls()
    forms = [_form(info) for info in infos]
    results = _kinds([form.result_range for form in forms], _ANY)
    assert all(low == 0 for low, _high in results), "a result's check is one unsigned compare"
    descriptors: list[int] = []
    ranges: list[int] = []
    for info, form in zip(infos, forms, strict=True):
        written = [VARIABLES.index(name) for name in form.writes]
        if written:  # a run of pairs of variables, from the first: copied a pair at a time
            assert written == list(range(written[0], written[0] + len(written)))
        assert len(written) % 2 == 0 and len(written) <= 4, "rl1_reading holds 4 writes"
        assert not (written and form.params), "one byte says the first of either"
        first = written[0] if written else len(ranges) // 2
        assert first < 256, "the descriptor's high byte holds it"
        descriptors.append(
            info.arity
            | (0x04 if BUILTINS[form_mnemonic(info)].waits else 0)
            | (0x08 if form.returns_value else 0)
            | (len(written) // 2) << 4
            | ((results.index(form.result_range) + 1 if form.result_range != _ANY else 0)
               << 6)
            | first << 8)
        for param in form.params:
            ranges += [param.low, param.high]
    return [
        "/* Each call's descriptor (spec/ilc.md 8.3 and 12), from vm/language.py: for each",
        "   call from RL1_OP_FIRST_CALL, a u16 in RL1_CALL_DESCRIPTORS of the bits below and,",
        "   in its high byte (RL1_CALL_FIRST_SHIFT), for a call with arguments the index in",
        "   RL1_PARAM_RANGES of its first parameter's range (low, and the span to high:",
        "   rl1_param_range), the others' following it; for one that writes reserved",
        "   variables (none takes arguments), the first of them, the others following it. */",
        "#define RL1_CALL_ARITY 0x03u       /* how many arguments it takes, 0 to 3 */",
        "#define RL1_CALL_STARTED 0x04u     /* it takes device time: started, then polled */",
        "#define RL1_CALL_SETS_R 0x08u      /* its result goes into R */",
        "#define RL1_CALL_PAIRS 0x30u       /* how many pairs of reserved variables it writes,",
        "                                      from rl1_reading's writes */",
        "#define RL1_CALL_PAIRS_SHIFT 4u",
        "#define RL1_CALL_RESULT 0xC0u      /* its result's range: 0 for any, else",
        "                                      0 .. RL1_RESULT_HIGH of it */",
        "#define RL1_CALL_RESULT_SHIFT 6u",
        "#define RL1_CALL_FIRST_SHIFT 8u    /* the high byte: where its ranges or writes start */",
        f"#define RL1_RESULT_HIGH(kind) {_select([high for _low, high in results], 'kind')}",
        f"#define RL1_CALL_COUNT {len(infos)}",
        "#define RL1_CALL_DESCRIPTORS \\",
        *_initializer([f"0x{word:04X}u" for word in descriptors]),
        f"#define RL1_PARAM_COUNT {len(ranges) // 2}",
        "#define RL1_PARAM_RANGES \\",
        *_initializer([f"{{{_c_int(low)}, {high - low}u}}"
                       for low, high in zip(ranges[::2], ranges[1::2], strict=True)]),
    ]


def form_mnemonic(info: isa.OpInfo) -> str:
    assert info.builtin is not None
    return info.builtin[0]


def render_c() -> str:
    """The opcodes as a C enum (RL1_OP_ and the mnemonic: RL1_OP_MOV, RL1_OP_CAMZ), the
    device features as the bits of a program's `features` (RL1_FEATURE_MOTION...), and
    each call's descriptor, between C_BEGIN and C_END."""
    opcodes = [f"    RL1_OP_{info.name} = 0x{info.opcode:02X},"
               for info in sorted(isa.OPCODES.values(), key=lambda i: i.opcode)]
    last_call = calls()[-1].opcode
    features = [f"    RL1_FEATURE_{feature.name} = 0x{1 << feature.value:02X},"
                for feature in Feature]
    known = sum(1 << feature.value for feature in Feature)
    return "\n".join([
        C_BEGIN,
        "",
        "/* The opcodes of spec/ilc.md 8.3. The built-in calls, which the callbacks are",
        f"   given, run from RL1_OP_{isa.OPCODES[isa.CALL_BASE].name} to "
        f"RL1_OP_{isa.OPCODES[last_call].name}: one for each form. */",
        "typedef enum rl1_opcode {",
        *opcodes,
        f"    RL1_OP_FIRST_CALL = 0x{isa.CALL_BASE:02X},",
        f"    RL1_OP_LAST_CALL = 0x{last_call:02X}",
        "} rl1_opcode;",
        "",
        f"/* A compact call (format 1.{isa.COMPACT_MINOR}, a byte an argument) is its call's "
        "opcode with this bit. */",
        f"#define RL1_COMPACT_CALL_BIT 0x{isa.COMPACT_CALL_BIT:02X}u",
        "",
        "/* The device features (spec/ilc.md 4.3): bits of rl1_program's `features`. */",
        "typedef enum rl1_feature {",
        *features,
        f"    RL1_FEATURES_KNOWN = 0x{known:02X}  /* every feature this format defines */",
        "} rl1_feature;",
        "",
        *render_descriptors(),
        "",
        C_END,
    ])


if __name__ == "__main__":
    print(render_c() if sys.argv[1:] == ["--c"] else render())
