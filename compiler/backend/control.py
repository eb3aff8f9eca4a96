"""Control-flow simplification: jumps threaded, branches folded, unreachable blocks
removed, blocks merged, in the source order the layout keeps.

Assumes: the IR is valid; blocks are in source order (lowering's order), which the code
generator lays out as they come, dropping a jump to the next block.
Keeps: the order of the blocks that remain (so the line map's lines never decrease,
spec/optimization.md section 4); every instruction; every handler's block; the budget
invariant (no path gets a jump it did not have: a jump is threaded past a block only
when that block's own jump is a real one, not a fall-through).

- A jump or branch to an empty block that only jumps on goes straight to where it goes.
- A jump to an empty block that only ends becomes the end.
- A branch whose two targets are one block becomes a jump.
- Blocks neither the entry nor a handler can reach go.
- A block entered only by a jump from the block before it joins that block.
"""

from __future__ import annotations

import dataclasses
from array import array

from . import flow, ir


def simplify_control(program: ir.Program) -> ir.Program:
    _remove_unreachable(program)
    following = program.following()
    threaded = False  # whether a terminator changed, and with it what is reachable
    for block in program:
        terminator = _threaded(program, following, block.terminator)
        if terminator is not block.terminator:
            block.terminator, threaded = terminator, True
    del following  # of the blocks before some go
    if threaded:
        _remove_unreachable(program)
    _merge(program)
    return program


def _threaded(program: ir.Program, following: dict[ir.BlockId, ir.BlockId | None],
              terminator: ir.Terminator) -> ir.Terminator:
    def final(target: ir.BlockId) -> ir.BlockId:
        seen = {target}
        while True:
            block = program.blocks[target]
            jump = block.terminator
            if block.instructions or not isinstance(jump, ir.Jump) \
                    or following[target] == jump.target or jump.target in seen:
                return target
            target = jump.target
            seen.add(target)

    if isinstance(terminator, ir.Branch):
        if_true, if_false = final(terminator.if_true), final(terminator.if_false)
        if if_true == if_false:
            return ir.Jump(if_true, terminator.line)
        if (if_true, if_false) == (terminator.if_true, terminator.if_false):
            return terminator  # as it was: a block's terminator is not made again
        return dataclasses.replace(terminator, if_true=if_true, if_false=if_false)
    if isinstance(terminator, ir.Jump):
        target = program.blocks[final(terminator.target)]
        if not target.instructions and isinstance(target.terminator, ir.End):
            return ir.End(terminator.line)
        if target.id == terminator.target:
            return terminator
        return ir.Jump(target.id, terminator.line)
    return terminator


def _remove_unreachable(program: ir.Program) -> None:
    reached = flow.reachable(program)
    for block_id in [block_id for block_id in program.blocks if block_id not in reached]:
        del program.blocks[block_id]


def _merge(program: ir.Program) -> None:
    """Each block entered only by a jump from the block before it joined to that block.
    Its predecessors are the places of its predecessors' blocks (flow.Places), each
    mapped to the block it has joined (`joined`): a list of them a block was 15 bytes a
    source byte of a branch a line."""
    entries = set(flow.roots(program))
    places = flow.Places(program)
    joined = array("I", range(len(places.blocks)))  # the place of the block each is in
    merged: list[ir.BlockId] = []
    previous: int | None = None
    for place, block in enumerate(places.blocks):
        if previous is not None and block.id not in entries:
            into = places.blocks[previous]
            preds = places.predecessors(place)
            if (isinstance(into.terminator, ir.Jump) and into.terminator.target == block.id
                    and len(preds) == 1 and joined[preds[0]] == previous):
                into.instructions = [*into.instructions, *block.instructions]
                into.terminator = block.terminator
                joined[place] = previous
                merged.append(block.id)
                continue
        previous = place
    for block_id in merged:
        del program.blocks[block_id]
