"""The final END left out: running past the last instruction ends the run as END does
(spec/ilc.md 4.1, a rule since format 1.0), so the last block's END is a byte, and an
instruction run, that no reader needs.

Assumes: the IR is valid; it runs last, on the layout the code generator keeps (a pass
after it that added a block behind the last one would make the end a fall-through).
Keeps: how every run ends (END cannot fault; the run ends normally either way, with the
same variables); every call; the budget invariant (one instruction fewer at the end).

Only when the last block holds an instruction: its start is then an instruction that a
jump or a handler may name, where an empty block's would be the offset past the code,
which the verifier refuses (spec/ilc.md, section 10, rule 17).
"""

from __future__ import annotations

from dataclasses import replace

from . import ir


def leave_out_final_end(program: ir.Program) -> ir.Program:
    last = next(reversed(program.blocks.values()), None)
    if last is not None and last.instructions and isinstance(last.terminator, ir.End):
        last.terminator = replace(last.terminator, written=False)
    return program
