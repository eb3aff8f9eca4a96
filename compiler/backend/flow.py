"""Facts about an IR program's control flow that several passes need.

Besides the edges of the terminators, control can leave a block where a lost-line event
is taken (right after a call, right after a jump taken: spec/language.md 7.7) for a
handler block, or for a fault when the handler is missing. Those event edges exist only
in programs that can set tracing mode 2 or 3.
"""

from __future__ import annotations

from array import array

from . import ir

TRACING_MODES_WITH_EVENTS = (2, 3)  # Table 4: the modes whose lost lines jump


def takes_events(program: ir.Program) -> bool:
    """Whether a lost-line event can ever reach the program: some (TRC m) sets mode 2 or
    3, or a mode held in a variable."""
    return any(
        isinstance(instruction, ir.Call) and instruction.mnemonic == "TRC"
        and (isinstance(instruction.args[0], ir.Var)
             or instruction.args[0].value in TRACING_MODES_WITH_EVENTS)
        for block in program for instruction in block.instructions
    )


def roots(program: ir.Program) -> list[ir.BlockId]:
    """Where control can enter from outside the terminators: the entry and the handlers."""
    return list(dict.fromkeys([program.entry, *program.handlers.values()]))


class Places:
    """The blocks of a program by their place in the layout, and the places of each
    block's predecessors (each once; a block that jumps to itself is its own), in
    arrays: a pass's flow over a long program holds a few bytes a block where a
    dictionary or list a block held a hundred or more (a block a line of `?A=#01` is
    7 source bytes). The predecessors are found when first asked for: the forward
    flows need only the places."""

    __slots__ = ("_first", "_preds", "blocks", "place")

    def __init__(self, program: ir.Program) -> None:
        self.blocks = list(program)
        self.place = {block.id: place for place, block in enumerate(self.blocks)}
        self._first: array[int] | None = None
        self._preds: array[int] | None = None

    def predecessors(self, place: int) -> array[int]:
        """The places of the predecessors of the block at `place`, in layout order."""
        if self._first is None or self._preds is None:
            self._first, self._preds = self._predecessors()
        return self._preds[self._first[place]:self._first[place + 1]]

    def _predecessors(self) -> tuple[array[int], array[int]]:
        """Where each block's predecessors start in the second array (counted first),
        and that array."""
        first = array("I", bytes(4 * (len(self.blocks) + 1)))
        for block in self.blocks:
            for target in _distinct(block.successors):
                first[self.place[target] + 1] += 1
        for place in range(len(self.blocks)):
            first[place + 1] += first[place]
        preds = array("I", bytes(4 * first[-1]))
        filled = array("I", first)
        for place, block in enumerate(self.blocks):
            for target in _distinct(block.successors):
                at = self.place[target]
                preds[filled[at]] = place
                filled[at] += 1
        return first, preds


def _distinct(targets: tuple[ir.BlockId, ...]) -> tuple[ir.BlockId, ...]:
    """A terminator's targets, each once (a branch may go to one block both ways)."""
    return targets[:1] if len(targets) == 2 and targets[0] == targets[1] else targets


def reachable(program: ir.Program) -> set[ir.BlockId]:
    """The blocks some path from the entry or a handler reaches."""
    seen: set[ir.BlockId] = set()
    work = roots(program)
    while work:
        block_id = work.pop()
        if block_id in seen:
            continue
        seen.add(block_id)
        work.extend(program.successors(block_id))
    return seen


def acc_dead_after(instructions: list[ir.Instruction], index: int,
                   terminator: ir.Terminator) -> bool:
    """Whether nothing from `instructions[index]` on (the terminator included) reads
    the accumulator before loading it again."""
    for instruction in instructions[index:]:
        if isinstance(instruction, ir.Load | ir.Compute):
            return True
        if isinstance(instruction, ir.Operate | ir.Store):
            return False
    return not isinstance(terminator, ir.StoreBranch)
