"""vm/c/rl1vm.h's opcode and feature constants are the ones vm/isa.py and vm/language.py
define: the header holds exactly the block `python -m rl1.vm.isa_table --c` writes."""

from __future__ import annotations

from support import ROOT

from rl1.vm import isa, isa_table
from rl1.vm.language import Feature

HEADER = (ROOT / "vm" / "c" / "rl1vm.h").read_text(encoding="utf-8")


def test_the_header_holds_the_generated_constants() -> None:
    assert isa_table.render_c() in HEADER, (
        "vm/c/rl1vm.h's opcode or feature constants differ from vm/isa.py: regenerate "
        "them with `python -m rl1.vm.isa_table --c` and paste them over the block between "
        "its markers")


def test_every_opcode_and_feature_has_its_constant() -> None:
    block = isa_table.render_c()
    for info in isa.OPCODES.values():
        assert f"    RL1_OP_{info.name} = 0x{info.opcode:02X}," in block
    for feature in Feature:
        assert f"    RL1_FEATURE_{feature.name} = 0x{1 << feature.value:02X}," in block
