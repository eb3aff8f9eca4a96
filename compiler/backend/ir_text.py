"""The IR as text: what `rl1c compile --emit ir` prints and the tests compare.

A module of its own, beside `ir.py`, because it names each block's predecessors from
`flow.Places`, which builds on `ir.py`.
"""

from __future__ import annotations

from .flow import Places
from .ir import Program


def format_program(program: Program) -> str:
    """The IR as stable text: a header, then each block in layout order with its
    predecessors (flow.Places's, in layout order; the handler table is not an edge) and
    one instruction a line, prefixed by its source line."""
    out = [f"entry {program.entry}"]
    out += [f"handler :{label} {program.handlers[label]}" for label in sorted(program.handlers)]
    places = Places(program)
    for place, block in enumerate(places.blocks):
        preds = [places.blocks[pred].id for pred in places.predecessors(place)]
        out.append("")
        comment = f"  ; from {', '.join(preds)}" if preds else ""
        out.append(f"{block.id}:{comment}")
        for item in [*block.instructions, block.terminator]:
            out.append(f"{item.line:6}  {item}")
    return "\n".join(out) + "\n"
