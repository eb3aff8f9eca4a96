"""The instruction table of spec/ilc.md, and the C VM's opcode and feature constants,
rendered from isa.OPCODES and language.Feature.

`python -m rl1.vm.isa_table` prints the table; tests/project/test_ilc_spec.py checks that
the spec holds exactly it, so the document cannot drift from the code. `python -m
rl1.vm.isa_table --c` prints the constants' block of vm/c/rl1vm.h, which
tests/c/test_c_constants.py holds equal to the header's.
"""

from __future__ import annotations

import sys

from . import isa
from .language import Feature

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
        return "mask, " + ", ".join(param.name for param in form.params)
    return ", ".join(_OPERAND_TEXT[operand] for operand in info.operands) or "—"


def serves(info: isa.OpInfo) -> str:
    if info.builtin is not None and info.name != "END":
        mnemonic, selector = info.builtin
        form = info.form
        assert form is not None
        words = " ".join(filter(None, [mnemonic, selector,
                                       ",".join(param.name for param in form.params)]))
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


def render_c() -> str:
    """The opcodes as a C enum (RL1_OP_ and the mnemonic: RL1_OP_MOV, RL1_OP_CAMZ), and
    the device features as the bits of a program's `features` (RL1_FEATURE_MOTION...),
    between C_BEGIN and C_END."""
    opcodes = [f"    RL1_OP_{info.name} = 0x{info.opcode:02X},"
               for info in sorted(isa.OPCODES.values(), key=lambda i: i.opcode)]
    last_call = max(info.opcode for info in isa.OPCODES.values()
                    if info.builtin is not None)
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
        "/* The device features (spec/ilc.md 4.3): bits of rl1_program's `features`. */",
        "typedef enum rl1_feature {",
        *features,
        f"    RL1_FEATURES_KNOWN = 0x{known:02X}  /* every feature this format defines */",
        "} rl1_feature;",
        "",
        C_END,
    ])


if __name__ == "__main__":
    print(render_c() if sys.argv[1:] == ["--c"] else render())
