"""The test vectors of spec/vectors: the compiler writes their exact bytes, the verifier
accepts them, the VM run on those bytes and the interpreter run on the source give
exactly the recorded outcome; together they use every opcode and every built-in form
with constant and with variable arguments, and reach every fault; and the committed
files are what the generator writes today."""

from __future__ import annotations

import json
import re
import sys
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROOT

from rl1.compiler.backend.driver import compile_text
from rl1.vm import ilc, isa
from rl1.vm.faults import FaultKind
from rl1.vm.language import VARIABLES
from rl1.vm.verifier import VerifyError, verify

VECTOR_DIR = ROOT / "spec" / "vectors"
sys.path.insert(0, str(VECTOR_DIR))

import cases  # noqa: E402  (spec/vectors is not a package: its modules need the path)
import generate  # noqa: E402
import oracle  # noqa: E402
from files import all_file_cases  # noqa: E402
from generate import Outcome, VectorError  # noqa: E402


def _load(key: str) -> list[dict[str, Any]]:
    """The runs ("vectors") or the verifier's files ("files") of every vector file."""
    vectors = []
    for path in sorted(VECTOR_DIR.glob("*.json")):
        document = json.loads(path.read_text(encoding="ascii"))
        assert document["format"] == generate.FORMAT, path
        assert document["group"] == path.stem, path
        vectors += document.get(key, [])
    return vectors


VECTORS = _load("vectors")
FILES = _load("files")
BY_NAME = {vector["name"]: vector for vector in VECTORS}
each_vector = pytest.mark.parametrize("vector", VECTORS, ids=[v["name"] for v in VECTORS])


def expected(vector: dict[str, Any], *, stripped: bool = False) -> Outcome:
    line = None if stripped or vector["status"] == "ok" else vector["fault_line"]
    return Outcome(vector["status"], line, tuple(vector["variables"]), tuple(
        (entry["time"], entry["call"], tuple(entry["args"]), tuple(entry["result"]))
        for entry in vector["trace"]), vector["executed"])


def instructions(data: bytes) -> list[isa.Instruction]:
    return list(verify(data).instructions)


# --- each vector -----------------------------------------------------------------------


def test_vectors_exist_and_have_unique_names() -> None:
    assert len(VECTORS) > 100
    assert len(BY_NAME) == len(VECTORS)


def test_the_readme_counts_the_vectors_of_each_file() -> None:
    readme = (VECTOR_DIR / "README.md").read_text(encoding="utf-8")
    listed = {name: int(count) for name, count
              in re.findall(r"^\| `(\w+)\.json` \| (\d+) \|", readme, re.MULTILINE)}
    documents = {path.stem: json.loads(path.read_text(encoding="ascii"))
                 for path in VECTOR_DIR.glob("*.json")}
    actual = {stem: len(document.get("vectors", document.get("files")))
              for stem, document in documents.items()}
    assert listed == actual


def hand_written(vector: dict[str, Any]) -> bool:
    """Whether the vector's source is intermediate code written by hand (.ils)."""
    return bool(vector["source_name"].endswith(".ils"))


@each_vector
def test_the_compiler_writes_the_bytes(vector: dict[str, Any]) -> None:
    if hand_written(vector):
        case = cases.Case("ils", vector["name"], "", vector["source"], {}, language="ils")
        full, stripped = generate.compile_both(case)
        assert (full.hex(), stripped.hex()) == (vector["ilc"], vector["ilc_stripped"])
        return
    # A vector of a newer format is the compiler's -O2 output (spec/vectors/README.md).
    level = 2 if bytes.fromhex(vector["ilc"])[5] >= isa.FUSED_MINOR else 0
    for key, strip in (("ilc", False), ("ilc_stripped", True)):
        compilation = compile_text(vector["source"], vector["source_name"], strip_debug=strip,
                                   level=level)
        assert compilation.output is not None, compilation.diagnostics
        assert compilation.output.hex() == vector[key], key


@each_vector
def test_the_verifier_accepts_the_bytes(vector: dict[str, Any]) -> None:
    full, stripped = bytes.fromhex(vector["ilc"]), bytes.fromhex(vector["ilc_stripped"])
    assert verify(full).image.debug is not None
    assert verify(stripped).image.debug is None
    assert ilc.strip_debug(ilc.decode(full)) == ilc.decode(stripped)


@each_vector
def test_the_vm_on_the_bytes_gives_the_outcome(vector: dict[str, Any]) -> None:
    for key, stripped in (("ilc", False), ("ilc_stripped", True)):
        outcome = generate.run_vm(bytes.fromhex(vector[key]), vector["sensors"],
                                  vector["budget"])
        assert generate.difference(expected(vector, stripped=stripped), outcome) is None, key


@each_vector
def test_the_interpreter_on_the_source_gives_the_outcome(vector: dict[str, Any]) -> None:
    if hand_written(vector) or not generate.interpretable(vector["sensors"]):
        pytest.skip("intermediate code, or losses after instruction counts: VM only")
    outcome = generate.run_interpreter(vector["source"], vector["sensors"], vector["budget"])
    assert generate.difference(expected(vector), outcome) is None


@each_vector
def test_the_fields_are_consistent(vector: dict[str, Any]) -> None:
    statuses = {kind.code: kind.exit_status for kind in FaultKind} | {"ok": 0}
    assert vector["exit_status"] == statuses[vector["status"]]
    assert (vector["fault_line"] == 0) == (vector["status"] == "ok")
    assert len(vector["variables"]) == len(VARIABLES)
    assert all(-32768 <= value <= 32767 for value in vector["variables"])
    assert re.fullmatch("[a-z0-9-]+", vector["name"])
    assert vector["source_name"] in (vector["name"] + ".rob", vector["name"] + ".ils")


@pytest.mark.parametrize("vector", FILES, ids=[f["name"] for f in FILES])
def test_the_verifier_does_what_each_file_vector_says(vector: dict[str, Any]) -> None:
    data = bytes.fromhex(vector["ilc"])
    if vector["accepted"]:
        verify(data)
        return
    with pytest.raises(VerifyError) as refusal:
        verify(data)
    assert refusal.value.offset == vector["offset"]
    assert re.search(generate.RULE_MESSAGES[vector["rule"]], refusal.value.message)


def test_every_rule_of_the_verifier_has_a_file_vector() -> None:
    assert {f["rule"] for f in FILES if not f["accepted"]} == set(generate.RULE_MESSAGES)


# --- coverage --------------------------------------------------------------------------


def test_every_opcode_appears_in_the_vectors() -> None:
    used = {instruction.info.opcode for vector in VECTORS
            for instruction in instructions(bytes.fromhex(vector["ilc_stripped"]))}
    missing = sorted(isa.OPCODES[opcode].name for opcode in set(isa.OPCODES) - used)
    assert missing == []


def test_every_builtin_form_has_constant_and_variable_arguments() -> None:
    masks: dict[str, set[int]] = {}
    for vector in VECTORS:
        for instruction in instructions(bytes.fromhex(vector["ilc_stripped"])):
            if instruction.info.builtin is not None and instruction.info.arity:
                mask = sum(1 << index for index, arg in enumerate(instruction.args)
                           if arg.is_var)
                masks.setdefault(instruction.info.name, set()).add(mask)
    for info in isa.OPCODES.values():
        if info.builtin is not None and info.arity:
            assert {0, (1 << info.arity) - 1} <= masks.get(info.name, set()), info.name


def test_every_fault_kind_is_reached() -> None:
    statuses = {vector["status"] for vector in VECTORS}
    # but an abort, which the firmware makes, not the program or its sensor script
    # (tests/c/test_run_control.py holds the two VMs to each other on it)
    assert statuses == {"ok"} | {kind.code for kind in FaultKind if kind is not FaultKind.ABORTED}


def test_every_range_checked_parameter_faults_below_and_above() -> None:
    """Which parameter a range fault is about, read from the data: the call's variable
    argument whose final value lies outside its parameter's range."""
    reached = set()
    for vector in VECTORS:
        if vector["status"] != "argument-range":
            continue
        for instruction in instructions(bytes.fromhex(vector["ilc_stripped"])):
            form = instruction.info.form
            if form is None:
                continue
            for arg, param in zip(instruction.args, form.params, strict=True):
                value = vector["variables"][arg.value] if arg.is_var else param.low
                if value < param.low:
                    reached.add((instruction.info.name, param.name, "below"))
                elif value > param.high:
                    reached.add((instruction.info.name, param.name, "above"))
    wanted = {(info.name, param.name, side) for info in isa.OPCODES.values()
              if info.form is not None for param in info.form.params
              if (param.low, param.high) != (-32768, 32767) for side in ("below", "above")}
    assert sorted(wanted - reached) == []


def _losses(vector: dict[str, Any]) -> set[tuple[int, str]]:
    """(tracing mode, motion in effect) of each loss the device recorded: the motion is
    the last MOV or MVI before the LINE LOST entry. Mode 0 records nothing, so a script
    that loses the line under TRC 0 counts for the moving MOV and the MVI the trace holds."""
    found = set()
    motion = None
    for entry in vector["trace"]:
        if entry["call"] in ("MOV", "MVI"):
            motion = entry["call"]
        elif entry["call"] == "LINE LOST":
            assert motion is not None
            found.add((entry["args"][0], motion))
    modes = {entry["args"][0] for entry in vector["trace"] if entry["call"] == "TRC"}
    if modes == {0} and vector["sensors"].get("line_lost"):
        found |= {(0, entry["call"]) for entry in vector["trace"]
                  if entry["call"] == "MVI" or (entry["call"] == "MOV" and any(entry["args"]))}
    return found


def test_every_tracing_mode_loses_the_line_during_mov_and_mvi() -> None:
    seen = set().union(*(_losses(vector) for vector in VECTORS))
    assert {(mode, command) for mode in range(4) for command in ("MOV", "MVI")} <= seen


def test_every_handler_is_taken_and_missed() -> None:
    """Modes 2 and 3 jump to :96-:99 (Table 4): each pair runs on in some vector (the
    handler was there) and faults in another (it was not)."""
    jumping = {(mode, command) for mode in (2, 3) for command in ("MOV", "MVI")}
    taken = set().union(*(_losses(v) for v in VECTORS if v["status"] == "ok"))
    missed = set().union(*(_losses(v) for v in VECTORS if v["status"] == "missing-handler"))
    assert jumping <= taken
    assert jumping <= missed


# --- the generator ---------------------------------------------------------------------


def test_the_files_are_what_the_generator_writes() -> None:
    files = generate.generate(cases.all_cases(), all_file_cases())
    stale = generate.stale_files(files)
    assert stale == [], ("run `.venv/bin/python spec/vectors/generate.py` and review the "
                         f"diff: {stale}")


def _case(**changes: Any) -> cases.Case:
    fields: dict[str, Any] = {"group": "test", "name": "probe", "covers": "",
                              "source": "A=1\n(MOV 1,1)\n(MOV 0,0)\n", "variables": {"A": 1}}
    return cases.Case(**(fields | changes))


def test_the_generator_accepts_a_right_case() -> None:
    vector = generate.build(_case(trace=((0, "MOV", (1, 1)), (None, "MOV", (0, 0)))))
    assert vector["variables"][VARIABLES.index("A")] == 1


@pytest.mark.parametrize("changes, problem", [
    ({"variables": {"A": 2}}, "variables A=1 (expected 2)"),
    ({"variables": {"A": 1, "%": 0}}, "names no variable ['%']"),
    ({"status": "budget", "fault_line": 2}, "status ok at line None, expected budget"),
    ({"trace": ((0, "MOV", (1, 2)),)}, "trace entry 0 0 MOV [1, 1], expected 0 MOV [1, 2]"),
    ({"trace": ((0, "MOV", (1, 1)),)}, "a trace of 2 entries, expected 1"),
    ({"source": "A=1\n#10\n"}, "does not compile: line 2: E0"),
    ({"source": "A=1 ' caf\u00e9\n"}, "ASCII text only"),
])
def test_the_generator_refuses_a_case_the_runs_contradict(changes: dict[str, Any],
                                                          problem: str) -> None:
    with pytest.raises(VectorError, match="probe: .*" + re.escape(problem)):
        generate.build(_case(**changes))


def test_the_generator_refuses_two_cases_of_one_name() -> None:
    with pytest.raises(VectorError, match="probe: two cases have this name"):
        generate.generate([_case(), _case()])


# --- the oracle ------------------------------------------------------------------------

int16 = st.integers(-32768, 32767)


@settings(max_examples=100, deadline=None)
@given(st.sampled_from(sorted(oracle.OPERATORS)), int16, int16)
def test_the_oracle_agrees_with_the_engines_on_any_values(op: str, a: int, b: int) -> None:
    """The oracle is a second opinion worth having only if it is right beyond the edge
    values the vectors pick: on any operands, the compiled code and the interpreter
    compute what it computes (the operands in variables, so any count reaches a shift)."""
    program = oracle.Straight([oracle.Assign("a", a), oracle.Assign("b", b),
                               oracle.Assign("C", "a", ((op, "b"),))])
    want = program.evaluate()
    compilation = compile_text(program.source(), "oracle.rob")
    assert compilation.output is not None
    vm = generate.run_vm(compilation.output, {}, 100)
    interpreter = generate.run_interpreter(program.source(), {}, 100)
    assert vm.variables == interpreter.variables == tuple(want[name] for name in VARIABLES)
