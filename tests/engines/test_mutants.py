"""The vectors catch the mistakes a C VM written from the spec is likely to make: each
mutant below is vm/machine.py broken in one such way, and some vector must fail on it.

A mutant is the reference VM's source with text replaced, loaded as a module of its own;
the vectors run on it through the generator's own runner, as on the real VM."""

from __future__ import annotations

import importlib.util
import sys
from typing import Any

import pytest
from support import ROOT
from test_vectors import VECTOR_DIR, VECTORS, expected

from rl1.vm.machine import Machine, State

sys.path.insert(0, str(VECTOR_DIR))
import generate  # spec/vectors is not a package: it needs the path

SOURCE = (ROOT / "vm" / "machine.py").read_text(encoding="utf-8")
IN_JUMP, IN_CONDITION = " " * 20, " " * 24  # the indentation of a jump's body, and a condition's
# (the conditional jumps: JZ, JGT, JLT and the superinstructions DJGT and SJZ/SJGT/SJLT)

Replacement = tuple[str, str, int]  # old text, new text, how often the old text occurs

MUTANTS: dict[str, list[Replacement]] = {
    "no event check at taken jumps": [
        ("b if hardware.pending is None else divert(take(), b)", "b", 6)],
    "no budget check at conditional jumps": [
        (f"{IN_CONDITION}if executed > budget:\n{IN_CONDITION}    break\n", "", 5)],
    "a handler jump counted as an instruction": [
        ("pc = start = divert(event, pc)", "pc = start = divert(event, pc); executed += 1", 1),
        (f"else divert(take(), b)\n{IN_CONDITION}if", f"else divert(take(), b)\n"
         f"{IN_CONDITION}executed += pc != b\n{IN_CONDITION}if", 5),
        (f"else divert(take(), b)\n{IN_JUMP}if", f"else divert(take(), b)\n"
         f"{IN_JUMP}executed += pc != b\n{IN_JUMP}if", 1)],
    "a negative or large shift count from R taken as 0": [
        ("_shift_left(_wrap(acc), cells[cell])",
         "_shift_left(_wrap(acc), _r0(cell, cells[cell]))", 1),
        ("count = cells[cell]\n", "count = _r0(cell, cells[cell])\n", 1),
        ("_shift_left(_wrap(acc), cells[a])", "_shift_left(_wrap(acc), _r0(a, cells[a]))", 1),
        ("count = cells[a]\n", "count = _r0(a, cells[a])\n", 1),
        ("\ndef run(", "\ndef _r0(cell: int, count: int) -> int:\n"
         "    return 0 if cell == R_CELL and not 0 <= count < 16 else count\n\n\ndef run(", 1)],
    "events taken only after calls that wait": [
        ("event = take()\n", "event = take() if site.waits else None\n", 1)],
    "the range check made before the budget check": [
        ("site = sites[a]\n", "site = sites[a]; self._arguments(site, cells)\n", 1)],
}


def mutant(name: str) -> type[Machine]:
    source = SOURCE
    for old, new, count in MUTANTS[name]:
        assert source.count(old) == count, f"{name}: {old!r} is not in machine.py {count}x"
        source = source.replace(old, new)
    module_name = "rl1.vm._mutant"
    spec = importlib.util.spec_from_loader(module_name, loader=None)
    assert spec is not None
    module = importlib.util.module_from_spec(spec)
    module.__package__ = "rl1.vm"
    sys.modules[module_name] = module  # dataclasses look their module up
    try:
        exec(compile(source, f"<{name}>", "exec"), module.__dict__)
    finally:
        del sys.modules[module_name]
    module.__dict__["State"] = State  # the states the runner compares with, not a copy of them
    machine: type[Machine] = module.Machine
    return machine


def _caught_by(vector: dict[str, Any], machine: type[Machine]) -> bool:
    outcome = generate.run_vm(bytes.fromhex(vector["ilc_stripped"]), vector["sensors"],
                              vector["budget"], machine)
    return generate.difference(expected(vector, stripped=True), outcome) is not None


@pytest.mark.parametrize("name", sorted(MUTANTS))
def test_some_vector_catches_the_mutant(name: str) -> None:
    machine = mutant(name)
    assert any(_caught_by(vector, machine) for vector in VECTORS), (
        f"every vector passes on a VM with {name}")


def test_the_unbroken_source_passes_every_vector() -> None:
    """The loading itself breaks nothing: the source as it is, loaded as a mutant is,
    passes every vector."""
    MUTANTS["unchanged"] = []
    try:
        machine = mutant("unchanged")
    finally:
        del MUTANTS["unchanged"]
    assert not any(_caught_by(vector, machine) for vector in VECTORS)
