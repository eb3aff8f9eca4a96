"""Copy propagation within a block: the loads and stores that move a value where it is;
and algebra with equal operands, which needs the same knowledge.

Assumes: the IR is valid (the accumulator is dead where a block starts).
Keeps: every instruction but the loads, stores and operations it drops or replaces;
what every variable holds after every instruction that remains.

Walking a block, each pass remembers the variables whose value the accumulator holds
(after `load A` or `store A`, until A or the accumulator changes).

`propagate_copies`: a load of one of them (`STV A; LDV A`, as `A=B+1; C=A` compiles)
and a store into one of them (`A=A`, or `B=A` after `A=B`) do nothing, and go. A load
followed by a commutative operation on one of them (`store d; load D; add d`, as
`D=D+d` compiles after `d=...`) becomes that operation on what the load named (`add
D`): one instruction instead of two. What each variable and the accumulator hold at
every point stays, and so does the control flow: nothing that constant folding or the
signs read changes (the optimizer relies on it, and a property test holds it).

`cancel_equal_operands`: an operation on one of them is algebra with equal operands
(spec/language.md 7.2: the 16-bit patterns are the same): `A&A` and `A|A` are A, and
go; `A-A` and `A^A` are 0, a load of 0 in the operation's place, which constant
folding carries on.
"""

from __future__ import annotations

from . import ir

COMMUTATIVE = "+&|^"
IDEMPOTENT = "&|"  # x op x is x
CANCELLING = "-^"  # x op x is 0


def propagate_copies(program: ir.Program) -> ir.Program:
    for block in program:
        block.instructions = _walk(block.instructions, copies=True)
    return program


def cancel_equal_operands(program: ir.Program) -> ir.Program:
    for block in program:
        block.instructions = _walk(block.instructions, copies=False)
    return program


def _walk(instructions: list[ir.Instruction], *, copies: bool) -> list[ir.Instruction]:
    """The block with the copies dropped (`copies`) or else its algebra with equal
    operands done."""
    out: list[ir.Instruction] = []
    holds: set[str] = set()  # the variables equal to the accumulator
    index = 0
    while index < len(instructions):
        instruction = instructions[index]
        after = instructions[index + 1] if index + 1 < len(instructions) else None
        index += 1
        if isinstance(instruction, ir.Load):
            source = instruction.source
            if isinstance(source, ir.Var) and source.name in holds:
                if copies:
                    continue
            elif (copies and isinstance(after, ir.Operate) and after.op in COMMUTATIVE
                    and isinstance(after.source, ir.Var) and after.source.name in holds):
                # `store d; load D; add d`: the accumulator holds d, so `add D`.
                out.append(ir.Operate(after.op, source, instruction.line))
                holds = set()
                index += 1
                continue
            else:
                holds = {source.name} if isinstance(source, ir.Var) else set()
        elif isinstance(instruction, ir.Store):
            if copies and instruction.target.name in holds:
                continue
            holds.add(instruction.target.name)
        elif not copies and isinstance(instruction, ir.Operate) \
                and isinstance(instruction.source, ir.Var) \
                and instruction.source.name in holds and instruction.op in IDEMPOTENT:
            continue
        elif not copies and isinstance(instruction, ir.Operate) \
                and isinstance(instruction.source, ir.Var) \
                and instruction.source.name in holds and instruction.op in CANCELLING:
            out.append(ir.Load(ir.Imm(0), instruction.line))
            holds = set()
            continue
        elif isinstance(instruction, ir.Operate | ir.Compute):
            holds = set()
        elif isinstance(instruction, ir.StepVar | ir.Move):
            holds.discard(instruction.target.name)
        else:
            holds.difference_update(instruction.form.writes)
        out.append(instruction)
    return out
