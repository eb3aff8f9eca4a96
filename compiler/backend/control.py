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

from . import flow, ir


def simplify_control(program: ir.Program) -> ir.Program:
    _remove_unreachable(program)
    following = program.following()
    for block in program:
        block.terminator = _threaded(program, following, block.terminator)
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
        return dataclasses.replace(terminator, if_true=if_true, if_false=if_false)
    if isinstance(terminator, ir.Jump):
        target = program.blocks[final(terminator.target)]
        if not target.instructions and isinstance(target.terminator, ir.End):
            return ir.End(terminator.line)
        return ir.Jump(target.id, terminator.line)
    return terminator


def _remove_unreachable(program: ir.Program) -> None:
    reached = flow.reachable(program)
    for block_id in [block_id for block_id in program.blocks if block_id not in reached]:
        del program.blocks[block_id]


def _merge(program: ir.Program) -> None:
    entries = set(flow.roots(program))
    preds = program.predecessors()
    kept: dict[ir.BlockId, ir.Block] = {}
    previous: ir.Block | None = None
    for block in program:
        if (previous is not None and isinstance(previous.terminator, ir.Jump)
                and previous.terminator.target == block.id and block.id not in entries
                and preds[block.id] == [previous.id]):
            previous.instructions = [*previous.instructions, *block.instructions]
            previous.terminator = block.terminator
            for target in dict.fromkeys(block.successors):
                preds[target] = [previous.id if pred == block.id else pred
                                 for pred in preds[target]]
            continue
        kept[block.id] = block
        previous = block
    program.blocks = kept
