"""What the vehicle may be doing at each point of a program: the tracing mode in effect
and the motion, as a bitset state, and what each call and each block does to it.
handler_edges.py runs it as a forward data-flow over the CFG, which gives both, and from
them the lost-line handler edges: where a lost guidance line can send the program.

The model (spec/language.md 7.5 and 7.7):
- the program starts in tracing mode 0 with the vehicle stopped; `(TRC m)` sets the
  mode, and `(TRC V)` may set any;
- `(MOV l,r)` with both speeds constant 0 stops the vehicle, with a non-zero constant
  moves it, with variables may do either; `(MVI ...)` runs to its distance and leaves
  the vehicle stopped (at once with a constant 0 cm); `(FRE)` and `(HLD)` stop it;
- a line lost while a MOV drives or an MVI runs becomes a pending event, taken at the
  next event point: right after a call, or after a jump, and jumps where Table 4
  (language.LOST_LINE_RULES) says. Mode 2 stops the vehicle first; in mode 3 the motion
  goes on (an MVI in the background, still an MVI in progress). The event may have been
  recorded at any moment since the previous event point, so each event point looks at
  the states before and after its call.
A call with the wrong number of arguments or an out-of-range constant (already an error)
changes nothing, and a line that could not be parsed is assumed to leave tracing off and
the vehicle stopped, so that neither cascades into warnings.

A state is a bitset: bit m (0-3) when mode m may be in effect, then STOPPED, MOVING (a
non-zero MOV in effect) and RUNNING (an MVI in progress).
"""

from __future__ import annotations

from rl1.compiler.frontend import ast
from rl1.vm.language import LOST_LINE_RULES

ALL_MODES = 0b1111
STOPPED = 1 << 4
MOVING = 1 << 5
RUNNING = 1 << 6
MOTION = STOPPED | MOVING | RUNNING
START = 1 << 0 | STOPPED
JUMPING_MODES = sum({1 << rule.mode for rule in LOST_LINE_RULES})  # modes 2 and 3

# What a call does to the device state: (kind, value), and where in its block.
_SET_MODES, _SET_MOTION, _MVI, _END = range(4)
Operation = tuple[int, int, int]  # (statement index, kind, value)
CALLS = frozenset({"TRC", "MOV", "MVI", "END", "FRE", "HLD"})  # the calls that may matter

# handler label -> (index of its first event point in the block, entry state)
Triggers = dict[int, tuple[int, int]]


def operation(call: ast.Call) -> tuple[int, int] | None:
    """What `call` does to the device state, None for nothing."""
    name = call.mnemonic.upper()
    args = call.args
    if name == "TRC":
        modes = _modes(args)
        return (_SET_MODES, modes) if modes else None
    if name == "MOV":
        motion = _motion(args)
        return (_SET_MOTION, motion) if motion else None
    if name == "MVI":
        if len(args) != 3:
            return None
        distance = args[2]
        stops_at_once = isinstance(distance, ast.Const) and distance.value == 0
        return (_SET_MOTION, STOPPED) if stops_at_once else (_MVI, STOPPED)
    if name == "END":
        return (_END, 0)
    return (_SET_MOTION, STOPPED) if name in ("FRE", "HLD") else None


def _modes(args: tuple[ast.Arg, ...]) -> int:
    if len(args) != 1:
        return 0
    (arg,) = args
    if isinstance(arg, ast.Var):
        return ALL_MODES
    return 1 << arg.value if isinstance(arg, ast.Const) and 0 <= arg.value <= 3 else 0


def _motion(args: tuple[ast.Arg, ...]) -> int:
    if len(args) != 2:
        return 0
    speeds = [arg.value for arg in args if isinstance(arg, ast.Const)]
    if any(not -12 <= speed <= 12 for speed in speeds):
        return 0
    if any(speeds):
        return MOVING
    return STOPPED if len(speeds) == 2 else STOPPED | MOVING  # a variable may be 0 or not


def run(operations: list[Operation], first_event: int | None,
        state: int) -> tuple[int, Triggers]:
    """A block's effect: its state at the end (before its `(END)`, if it has one) and the
    handlers a lost line may jump to from it, each with the state it enters with and the
    block's first event point where it may. Only the block's first event point and those
    of its operations need a look: the state changes nowhere else."""
    triggers: Triggers = {}
    if first_event is not None and (not operations or operations[0][0] != first_event):
        _lost_line((state,), state, False, first_event, triggers)
    for index, kind, value in operations:
        if kind == _END:
            break
        before = state
        state = state & (MOTION if kind == _SET_MODES else ALL_MODES) | value
        # A pending event may have been recorded before, during or after this call.
        if kind == _MVI:
            _lost_line((before, before & ALL_MODES | RUNNING, state), state, True, index,
                       triggers)
        else:
            _lost_line((before, state), state, False, index, triggers)
    return state, triggers


def _lost_line(recorded: tuple[int, ...], now: int, from_mvi: bool, index: int,
               triggers: Triggers) -> None:
    """The handlers an event taken at this event point may jump to, and the state each
    is entered with: the tracing mode stays as it is now; mode 3 keeps the motion now in
    effect (an MVI that lost the line here goes on in the background), mode 2 stops it."""
    under_mov = under_mvi = 0  # the modes a line may be lost in, during MOV and MVI
    for seen in recorded:
        if seen & MOVING:
            under_mov |= seen
        if seen & RUNNING:
            under_mvi |= seen
    if not (under_mov | under_mvi) & JUMPING_MODES:
        return
    modes = now & ALL_MODES
    for rule in LOST_LINE_RULES:
        modes_then = under_mvi if rule.command == "MVI" else under_mov
        if not modes_then & 1 << rule.mode:
            continue
        if rule.stops:
            entry = modes | STOPPED
        elif rule.command == "MVI" and from_mvi:
            entry = modes | RUNNING  # the MVI that lost the line runs on in the background
        else:
            entry = now
        first, entries = triggers.get(rule.label, (index, 0))
        triggers[rule.label] = (first, entries | entry)
