"""The intermediate representation between the checked AST and the .ilc code.

A program is an ordered set of basic blocks. Instructions mirror the accumulator machine
of vm/isa.py (load, operate, store, step, call) but name variables by letter and jump to
blocks, not addresses; every instruction carries the source line it came from. Control
leaves a block only through its terminator: a jump, a two-way branch or the end. Nothing
falls through implicitly; the code generator drops a jump to the block laid out next.

The accumulator is dead where a block starts: a block reads it only after loading it
(each statement's load-operate-store lies within one block), so passes reason about it
block by block. Passes rewrite the IR in place: `Program.blocks` maps each block's id to
the block, in layout order, and a block's instructions are a list of small frozen
dataclasses, so a pass replaces instructions and terminators rather than mutating them.
A pass also replaces a block's list rather than changing it in place: the blocks without
instructions share one (`NO_INSTRUCTIONS`). `validate` states the invariants every pass
must keep.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import cache, lru_cache

from rl1.compiler.frontend.ast import BinaryOperator, Relation, Step
from rl1.vm.language import BUILTINS, HANDLER_LABELS, VARIABLE_INDEX, Form

BlockId = str
"""`Lnn` for the block a source label `:nn` starts, `Bn` for the others."""


@cache  # one string a label, however many jumps name it
def label_block(number: int) -> BlockId:
    return f"L{number:02d}"


# Operands ---------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Var:
    """A variable, by its letter (builtins.VARIABLES)."""

    name: str

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True)
class Imm:
    """A 16-bit signed immediate."""

    value: int

    def __str__(self) -> str:
        return str(self.value)


@dataclass(frozen=True, slots=True)
class Result:
    """The result register R: the value of the last value-returning call."""

    def __str__(self) -> str:
        return "R"


R = Result()

Operand = Var | Imm | Result
Argument = Var | Imm


# Instructions -----------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Load:
    """acc = source."""

    source: Operand
    line: int

    def __str__(self) -> str:
        return f"load {self.source}"


OPERATOR_NAMES: dict[BinaryOperator, str] = {
    "+": "add", "-": "sub", "&": "and", "|": "or", "^": "xor", "<": "shl", ">": "shr",
}


@dataclass(frozen=True, slots=True)
class Operate:
    """acc = acc op source."""

    op: BinaryOperator
    source: Operand
    line: int

    def __str__(self) -> str:
        return f"{OPERATOR_NAMES[self.op]} {self.source}"


@dataclass(frozen=True, slots=True)
class Store:
    """target = acc."""

    target: Var
    line: int

    def __str__(self) -> str:
        return f"store {self.target}"


@dataclass(frozen=True, slots=True)
class StepVar:
    """target++ or target--, without touching acc."""

    target: Var
    step: Step
    line: int

    def __str__(self) -> str:
        return f"{'inc' if self.step == '++' else 'dec'} {self.target}"


@dataclass(frozen=True, slots=True)
class Call:
    """A built-in call other than END; one that returns a value sets R. `compact` (-O2,
    once its constants fit a byte each) is written as the compact call of format 1.3."""

    mnemonic: str
    selector: str | None
    args: tuple[Argument, ...]
    line: int
    compact: bool = False

    @property
    def form(self) -> Form:
        """The built-in form called (valid IR calls only forms that exist)."""
        form = _call_form(self.mnemonic, self.selector)
        assert form is not None
        return form

    @property
    def returns_value(self) -> bool:
        form = _call_form(self.mnemonic, self.selector)
        return form is not None and form.returns_value

    def __str__(self) -> str:
        words = [self.mnemonic, *([self.selector] if self.selector else [])]
        text = ("compact call " if self.compact else "call ") + " ".join(words)
        return text + (" " + ", ".join(map(str, self.args)) if self.args else "")


@lru_cache(maxsize=256)  # bounded: a malformed IR may name any number of built-ins
def _call_form(mnemonic: str, selector: str | None) -> Form | None:
    """BUILTINS' form lookup, which the passes and `validate` make for every call they
    pass: None when the name or the selector names no form."""
    builtin = BUILTINS.get(mnemonic)
    return builtin.form(selector) if builtin else None


@dataclass(frozen=True, slots=True)
class Move:
    """target = source, without touching acc (a superinstruction of -O2)."""

    target: Var
    source: Operand
    line: int

    def __str__(self) -> str:
        return f"move {self.target}, {self.source}"


@dataclass(frozen=True, slots=True)
class Compute:
    """acc = first op second: an expression's load and first operation in one (a
    superinstruction of -O2)."""

    first: Var | Result
    op: BinaryOperator
    second: Var | Imm
    line: int

    def __str__(self) -> str:
        return f"load {self.first} {OPERATOR_NAMES[self.op]} {self.second}"


Instruction = Load | Operate | Store | StepVar | Call | Move | Compute


# Terminators ------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Jump:
    target: BlockId
    line: int

    @property
    def targets(self) -> tuple[BlockId, ...]:
        return (self.target,)

    def __str__(self) -> str:
        return f"jump {self.target}"


class _TwoWay:
    """A terminator that goes to `if_true` or to `if_false`: the branches."""

    __slots__ = ()
    if_true: BlockId
    if_false: BlockId

    @property
    def targets(self) -> tuple[BlockId, ...]:
        return (self.if_true, self.if_false)


@dataclass(frozen=True, slots=True)
class Branch(_TwoWay):
    """Go to `if_true` when `var` compares with zero as `relation` says, else `if_false`."""

    var: Var
    relation: Relation
    if_true: BlockId
    if_false: BlockId
    line: int

    def __str__(self) -> str:
        return f"if {self.var}{self.relation}0 then {self.if_true} else {self.if_false}"


@dataclass(frozen=True, slots=True)
class StoreBranch(_TwoWay):
    """var = acc, then go to `if_true` when var compares with zero as `relation` says,
    else `if_false` (a superinstruction of -O2)."""

    var: Var
    relation: Relation
    if_true: BlockId
    if_false: BlockId
    line: int

    def __str__(self) -> str:
        return (f"store {self.var}; if {self.var}{self.relation}0 then {self.if_true} "
                f"else {self.if_false}")


@dataclass(frozen=True, slots=True)
class DecrementBranch(_TwoWay):
    """var--, then go to `if_true` when var > 0, else `if_false` (a superinstruction of
    -O2, for counted loops)."""

    var: Var
    if_true: BlockId
    if_false: BlockId
    line: int

    def __str__(self) -> str:
        return f"dec {self.var}; if {self.var}>0 then {self.if_true} else {self.if_false}"


@dataclass(frozen=True, slots=True)
class End:
    """The end of the run: an END, or with `written` False (the last block's, from -O1
    on: final_end.py) none, as running past the last instruction ends the run alike."""

    line: int
    written: bool = True

    @property
    def targets(self) -> tuple[BlockId, ...]:
        return ()

    def __str__(self) -> str:
        return "end" if self.written else "end (past the last instruction)"


Terminator = Jump | Branch | StoreBranch | DecrementBranch | End


# Blocks and programs ----------------------------------------------------------------


NO_INSTRUCTIONS: list[Instruction] = []
"""The one list of every block without instructions, never changed (`validate` says when
it was): a list a block of a jump a line, `#01`, was 14 bytes a source byte."""


@dataclass(slots=True)
class Block:
    id: BlockId
    instructions: list[Instruction]
    terminator: Terminator

    @property
    def successors(self) -> tuple[BlockId, ...]:
        return self.terminator.targets


@dataclass(slots=True)
class Program:
    """Blocks in layout order (the entry block first); `handlers` maps each handler label
    :96-:99 the program defines to its block."""

    blocks: dict[BlockId, Block]
    entry: BlockId
    handlers: dict[int, BlockId] = field(default_factory=dict)

    def __iter__(self) -> Iterator[Block]:
        return iter(self.blocks.values())

    def successors(self, block_id: BlockId) -> tuple[BlockId, ...]:
        return self.blocks[block_id].successors

    def following(self) -> dict[BlockId, BlockId | None]:
        """The block laid out after each one (None after the last): where it falls
        through, so that a jump to it costs no instruction."""
        return {block.id: following for block, following in self.laid_out()}

    def laid_out(self) -> Iterator[tuple[Block, BlockId | None]]:
        """Each block in layout order with the id of the block laid out after it (None
        after the last), for a walk that needs no dictionary of them (one was 12 bytes a
        source byte of `#01` lines while the IR was validated)."""
        blocks = iter(self.blocks.values())
        block = next(blocks, None)
        while block is not None:
            after = next(blocks, None)
            yield block, None if after is None else after.id
            block = after


# Invariants -------------------------------------------------------------------------


def validate(program: Program) -> list[str]:
    """Every broken invariant, as a message naming the block; empty when the IR is
    well formed. The code generator relies on all of these."""
    problems: list[str] = []
    if NO_INSTRUCTIONS:
        problems.append(f"the blocks' shared empty list holds {NO_INSTRUCTIONS[0]}: a pass "
                        "changed a block's list in place, where it must replace it")
    if next(iter(program.blocks), None) != program.entry:
        problems.append(f"the entry block {program.entry} is not the first block")
    blocks = program.blocks
    for block_id, block in blocks.items():
        if block.id != block_id:
            problems.append(f"block {block.id} is filed under the id {block_id}")
        for problem in _block_problems(block):
            problems.append(f"{block_id}: {problem}")
        if isinstance(block.terminator, Terminator):
            for target in block.terminator.targets:
                if target not in blocks:
                    problems.append(f"{block_id}: jumps to {target}, which is not a block")
    problems.extend(_decreasing_lines(program))
    problems.extend(_ends_not_written(program))
    for label, block_id in program.handlers.items():
        if label not in HANDLER_LABELS:
            problems.append(f"handler :{label} is not one of :96-:99")
        if block_id not in blocks:
            problems.append(f"handler :{label} names {block_id}, which is not a block")
    return problems


def _ends_not_written(program: Program) -> Iterator[str]:
    """An end left unwritten only where the run passes the last instruction: in the last
    block, after an instruction of its own (an empty block's start would be the offset
    past the code, which no jump or handler may name: spec/ilc.md, section 10)."""
    last = next(reversed(program.blocks.values()), None)
    for block in program:
        if isinstance(block.terminator, End) and not block.terminator.written \
                and (block is not last or not block.instructions):
            yield f"{block.id}: its end is left unwritten, but the run would not pass the " \
                  "last instruction there"


def _decreasing_lines(program: Program) -> Iterator[str]:
    """Lines never decrease along the code as the generator lays it out (spec/ilc.md
    4.4): the blocks in order, each one's instructions, then its terminator unless that
    is a jump to the next block, which is left out."""
    previous = 0
    for block, following in program.laid_out():
        terminator = block.terminator
        left_out = isinstance(terminator, Jump) and terminator.target == following
        for item in block.instructions if left_out else (*block.instructions, terminator):
            if item.line < previous:
                yield f"{block.id}: line {item.line} comes after line {previous}"
            else:
                previous = item.line


def _block_problems(block: Block) -> Iterator[str]:
    terminator = block.terminator
    if not isinstance(terminator, Terminator):
        yield f"ends with {terminator!r}, which is not a terminator"
    result_set = False  # whether R holds a value here (only a call within the block sets it)
    loaded = False  # whether acc holds a value here: it is dead where a block starts
    for instruction in block.instructions:
        if not isinstance(instruction, Instruction):
            yield f"holds {instruction!r}, which is not an instruction"
            continue
        for operand in operands(instruction):
            match operand:
                case Var(name=name) if name not in VARIABLE_INDEX:
                    yield f"line {instruction.line}: `{name}` is not a variable"
                case Imm(value=value) if not -0x8000 <= value <= 0x7FFF:
                    yield f"line {instruction.line}: {value} does not fit 16 bits"
                case Result() if not result_set:
                    yield f"line {instruction.line}: `{instruction}` reads R before a call sets it"
        match instruction:
            case Load() | Compute():
                loaded = True
            case Operate() | Store() if not loaded:
                yield f"line {instruction.line}: `{instruction}` reads acc before a load sets it"
            case Call():
                form = _call_form(instruction.mnemonic, instruction.selector)
                yield from _call_problems(instruction, form)
                result_set = form is not None and form.returns_value
    if isinstance(terminator, StoreBranch) and not loaded:
        yield f"line {terminator.line}: `{terminator}` reads acc before a load sets it"
    if isinstance(terminator, Branch | StoreBranch | DecrementBranch) \
            and terminator.var.name not in VARIABLE_INDEX:
        yield f"branches on `{terminator.var.name}`, which is not a variable"


def operands(instruction: Instruction) -> tuple[Operand, ...]:
    """What an instruction names: the variables it reads or writes, constants and R (a
    call's reserved variables left out)."""
    match instruction:
        case Load(source=source) | Operate(source=source):
            return (source,)
        case Store(target=target) | StepVar(target=target):
            return (target,)
        case Move():
            return (instruction.target, instruction.source)
        case Compute():
            return (instruction.first, instruction.second)
        case Call():
            return instruction.args


def _call_problems(call: Call, form: Form | None) -> Iterator[str]:
    """What is wrong with a call of `form` (None when its name and selector name none)."""
    if form is None or call.mnemonic == "END":
        yield f"line {call.line}: `{call}` is not a built-in form (END is a terminator)"
        return
    if len(call.args) != len(form.params):
        yield f"line {call.line}: `{call}` takes {len(form.params)} arguments"
        return
    for arg, param in zip(call.args, form.params, strict=True):
        if isinstance(arg, Imm) and not param.low <= arg.value <= param.high:
            yield f"line {call.line}: `{call}`: {param.name} must lie in {param.low}..{param.high}"
        if call.compact and isinstance(arg, Imm) and not -0x80 <= arg.value <= 0x7F:
            yield f"line {call.line}: `{call}`: {param.name} does not fit a byte"
