"""What a block's statements do, summarized once for all the data-flow rules: the calls
that change the device state (device.py), the reserved variables read and written
(reserved.py), and whether the block observes the world (loops.py).

"Observing" is the checker's word for a call through which a program can see the world
change or let device time pass: a call that returns a reading or writes reserved
variables (KYO, IMG, CAM R, ULT, INP, FZI), or one the device takes time over (`waits`
in vm/language.py: MVI, TIM, ORG, STR, STL, STX, ROT, IMG, CAM, ULT). A loop without one
spins at the speed of the interpreter, blind. For `(CAM ...)` and `(ULT ...)` a call is
taken to do what any of their forms does: the summary never resolves selectors.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

from rl1.compiler.frontend import ast
from rl1.vm.language import BUILTINS, RESERVED_VARIABLES

from . import device

RESERVED_BIT = {name: 1 << index for index, name in enumerate(RESERVED_VARIABLES)}
ALL_RESERVED = (1 << len(RESERVED_VARIABLES)) - 1


@dataclass(slots=True, eq=False)
class BlockEffects:
    """What a block (or a run of statements) does. Shared, never changed, and equal only
    to itself: a memo key (incremental.py)."""

    operations: list[device.Operation]  # the calls that change the device state
    # The first event point, where a pending lost line is taken: the first statement
    # that makes a call (right after it, before an assignment stores) or jumps.
    first_event: int | None
    reads: int  # reserved variables read anywhere in the block (RESERVED_BIT bits)
    # (statement index, reserved variables its calls write, those its store writes)
    writes: list[tuple[int, int, int]]
    observes: bool
    calls_unknown: bool  # whether a statement calls no built-in (maybe a misspelt `(END)`)

    @staticmethod
    def nothing() -> BlockEffects:
        return BlockEffects([], None, 0, [], False, False)


# A run of one line's statements that lies in a single block: the statements, what they
# do (indices counted from the run's first statement; None for nothing), and whether the
# run ends its block (with a jump or `(END)`). A plain tuple: a line makes one or more.
Segment = tuple[tuple[ast.Statement, ...], BlockEffects | None, bool]


class _CallFacts(NamedTuple):
    writes: int
    observes: bool
    device: bool  # whether device.operation may find something in it


def _facts_of(name: str) -> _CallFacts:
    builtin = BUILTINS.get(name.upper())
    if builtin is None:
        return _CallFacts(0, False, False)
    writes = 0
    for form in builtin.forms:
        for variable in form.writes:
            writes |= RESERVED_BIT[variable]
    observes = builtin.waits or any(form.returns_value or form.writes for form in builtin.forms)
    return _CallFacts(writes, observes, builtin.mnemonic in device.CALLS)


_FACTS = {builtin.mnemonic: _facts_of(builtin.mnemonic) for builtin in BUILTINS.values()}


def _facts(call: ast.Call) -> _CallFacts:
    facts = _FACTS.get(call.mnemonic)
    if facts is None:
        facts = _facts_of(call.mnemonic)
        if call.mnemonic.upper() in BUILTINS:  # remember other spellings of built-ins only
            _FACTS[call.mnemonic] = facts
    return facts


def reserved_writes(call: ast.Call) -> int:
    """The reserved variables the call sets, as RESERVED_BIT bits."""
    return _facts(call).writes


def combine(parts: Sequence[tuple[int, BlockEffects]]) -> BlockEffects:
    """The effects of a block from those of its runs, each with the index in the block
    of its first statement. Summaries are shared, never changed, so one run's is reused
    as it is."""
    combining = Combining()
    for offset, part in parts:
        combining.add(offset, part)
    return combining.result()


class Combining:
    """`combine` as the runs come, holding their combined effects rather than each run's
    (checker/streaming.py: a block of a million lines that each write a reserved
    variable held a million summaries until it ended)."""

    __slots__ = ("_alone", "_calls_unknown", "_first_event", "_observes", "_operations",
                 "_reads", "_runs", "_writes")

    def __init__(self) -> None:
        self._runs = 0
        self._alone: BlockEffects | None = None  # the only run's, at offset 0
        self._operations: list[device.Operation] = []
        self._writes: list[tuple[int, int, int]] = []
        self._first_event: int | None = None
        self._reads = 0
        self._observes = self._calls_unknown = False

    def add(self, offset: int, part: BlockEffects) -> None:
        """Add the effects of the run whose first statement is at `offset`."""
        self._runs += 1
        self._alone = part if self._runs == 1 and offset == 0 else None
        if self._first_event is None and part.first_event is not None:
            self._first_event = offset + part.first_event
        if part.operations:
            self._operations += [(offset + index, kind, value)
                                 for index, kind, value in part.operations]
        if part.writes:
            self._writes += [(offset + index, by_calls, by_store)
                             for index, by_calls, by_store in part.writes]
        self._reads |= part.reads
        self._observes = self._observes or part.observes
        self._calls_unknown = self._calls_unknown or part.calls_unknown

    @property
    def empty(self) -> bool:
        """Whether no run was added."""
        return not self._runs

    def result(self) -> BlockEffects:
        """The block's effects: the only run's itself, or the runs' combined."""
        if self._alone is not None:
            return self._alone
        if self.empty:
            return BlockEffects.nothing()
        return BlockEffects(self._operations, self._first_event, self._reads, self._writes,
                            self._observes, self._calls_unknown)


def line_segments(statements: tuple[ast.Statement, ...]) -> tuple[Segment, ...]:
    """A line's statements cut after each jump and `(END)`, each run summarized. What a
    run does depends on its statements alone, not on the line's number, so the language
    server keeps these across edits (incremental.LineMemo)."""
    segments: list[Segment] = []
    start = 0
    for index, statement in enumerate(statements):
        if isinstance(statement, ast.Goto | ast.CondJump) or ast.is_end(statement):
            run = statements[start : index + 1]
            segments.append((run, summarize(run), True))
            start = index + 1
    if start < len(statements):
        run = statements[start:]
        segments.append((run, summarize(run), False))
    return tuple(segments)


def _summary(operations: list[device.Operation], first_event: int | None, reads: int,
             writes: list[tuple[int, int, int]], observes: bool,
             calls_unknown: bool) -> BlockEffects | None:
    """A run's effects; None for a run without calls, jumps or reserved variables."""
    if first_event is None and not reads and not writes:
        return None  # no calls either: nothing observes, and there are no operations
    return BlockEffects(operations, first_event, reads, writes, observes, calls_unknown)


def summarize(statements: Sequence[ast.Statement]) -> BlockEffects | None:
    """The effects of a block's statements, in one pass (the checker's hottest loop);
    None for statements without calls, jumps or reserved variables."""
    operations: list[device.Operation] = []
    first_event: int | None = None
    writes: list[tuple[int, int, int]] = []
    reads = 0
    observes = calls_unknown = False
    bit = RESERVED_BIT.get
    known = _FACTS.get
    var, call_type = ast.Var, ast.Call
    for index, statement in enumerate(statements):
        if isinstance(statement, ast.Assign):
            by_calls = 0
            calls = False
            operand: ast.Operand = statement.first
            rest = statement.rest
            position = 0
            while True:
                if isinstance(operand, var):
                    reads |= bit(operand.name, 0)
                elif isinstance(operand, call_type):
                    calls = True
                    facts = known(operand.mnemonic) or _facts(operand)
                    for arg in operand.args:
                        if isinstance(arg, var):
                            reads |= bit(arg.name, 0)
                    by_calls |= facts.writes
                    observes = observes or facts.observes
                if position == len(rest):
                    break
                operand = rest[position].operand
                position += 1
            if calls and first_event is None:
                first_event = index
            by_store = bit(statement.target.name, 0)
            if by_calls or by_store:
                writes.append((index, by_calls, by_store))
        elif isinstance(statement, ast.CallStmt):
            if first_event is None:
                first_event = index
            call = statement.call
            known_facts = known(call.mnemonic)
            if known_facts is None:
                calls_unknown = calls_unknown or call.mnemonic.upper() not in BUILTINS
            facts = known_facts or _facts(call)
            for arg in call.args:
                if isinstance(arg, var):
                    reads |= bit(arg.name, 0)
            if facts.writes:
                writes.append((index, facts.writes, 0))
            observes = observes or facts.observes
            if facts.device:
                operation = device.operation(call)
                if operation is not None:
                    operations.append((index, *operation))
        elif isinstance(statement, ast.CondJump):
            if first_event is None:
                first_event = index
            reads |= bit(statement.var.name, 0)
        elif isinstance(statement, ast.IncDec):
            by_store = bit(statement.target.name, 0)
            if by_store:
                reads |= by_store
                writes.append((index, 0, by_store))
        elif first_event is None:  # a jump
            first_event = index
    return _summary(operations, first_event, reads, writes, observes, calls_unknown)
