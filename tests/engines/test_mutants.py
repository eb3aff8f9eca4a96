"""The vectors catch the mistakes a C VM written from the spec is likely to make: each
mutant below is the reference VM (vm/machine.py) broken in one such way, written as a
subclass that overrides one of its steps, and some vector must fail on it.

The vectors run on a mutant through the generator's own runner, as on the real VM. A
mutant overrides methods by name, so a test also checks that each name is still one
of Machine's: a renamed method would otherwise leave a mutant that mutates nothing."""

from __future__ import annotations

import sys
from typing import Any

import pytest
from test_vectors import VECTOR_DIR, VECTORS, expected

from rl1.vm import isa
from rl1.vm.language import BUILTINS
from rl1.vm.machine import Machine

sys.path.insert(0, str(VECTOR_DIR))
import generate  # spec/vectors is not a package: it needs the path

CONDITIONAL_JUMPS = {"JZ", "JGT", "JLT", "DJGT", "SJZ", "SJGT", "SJLT"}


def _at_hand(machine: Machine) -> isa.Instruction:
    """The instruction a machine is executing (its pc has moved past it)."""
    return machine.program.instructions[machine.pc - 1]


class NoEventCheckAtTakenJumps(Machine):
    def _jump(self, target: int) -> None:
        self._watchdog()
        self.pc = self.program.index_of[target]  # the event point forgotten


class NoBudgetCheckAtConditionalJumps(Machine):
    def _watchdog(self) -> None:
        if _at_hand(self).info.name not in CONDITIONAL_JUMPS:
            super()._watchdog()


class HandlerJumpCountedAsAnInstruction(Machine):
    def _event_point(self, resume: int) -> int:
        going = super()._event_point(resume)
        if going != resume:
            self.executed += 1
        return going


class ShiftCountFromROutOfRangeTakenAsZero(Machine):
    def _operator_operands(self, instruction: isa.Instruction) -> tuple[int, int]:
        left, right = super()._operator_operands(instruction)
        opcode = instruction.info.opcode
        shifts = isa.ALU_OPERATORS[opcode & 7] in ("<", ">")
        if shifts and opcode & ~7 == isa.ALU_RESULT and not 0 <= right < 16:
            return left, 0
        return left, right


class EventsTakenOnlyAfterCallsThatWait(Machine):
    def _event_point(self, resume: int) -> int:
        builtin = _at_hand(self).info.builtin
        if builtin is not None and not BUILTINS[builtin[0]].waits:
            return resume
        return super()._event_point(resume)


class RangeCheckBeforeBudgetCheck(Machine):
    def _call(self, instruction: isa.Instruction) -> None:
        self._arguments(instruction)
        super()._call(instruction)


MUTANTS: dict[str, type[Machine]] = {
    "no event check at taken jumps": NoEventCheckAtTakenJumps,
    "no budget check at conditional jumps": NoBudgetCheckAtConditionalJumps,
    "a handler jump counted as an instruction": HandlerJumpCountedAsAnInstruction,
    "a negative or large shift count from R taken as 0": ShiftCountFromROutOfRangeTakenAsZero,
    "events taken only after calls that wait": EventsTakenOnlyAfterCallsThatWait,
    "the range check made before the budget check": RangeCheckBeforeBudgetCheck,
}


def _caught_by(vector: dict[str, Any], machine: type[Machine]) -> bool:
    outcome = generate.run_vm(bytes.fromhex(vector["ilc_stripped"]), vector["sensors"],
                              vector["budget"], machine)
    return generate.difference(expected(vector, stripped=True), outcome) is not None


@pytest.mark.parametrize("name", sorted(MUTANTS))
def test_some_vector_catches_the_mutant(name: str) -> None:
    assert any(_caught_by(vector, MUTANTS[name]) for vector in VECTORS), (
        f"every vector passes on a VM with {name}")


@pytest.mark.parametrize("name", sorted(MUTANTS))
def test_the_mutant_overrides_methods_the_machine_has(name: str) -> None:
    overridden = {attribute for attribute, value in vars(MUTANTS[name]).items()
                  if callable(value)}
    assert overridden and overridden <= set(vars(Machine)), (
        f"{name}: {sorted(overridden - set(vars(Machine)))} are not Machine's methods")


def test_the_unbroken_machine_passes_every_vector() -> None:
    """The runner itself breaks nothing: the VM as it is passes every vector."""
    assert not any(_caught_by(vector, Machine) for vector in VECTORS)
