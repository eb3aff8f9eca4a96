"""Write the test vectors, spec/vectors/GROUP.json, from the cases of cases.py.

    .venv/bin/python spec/vectors/generate.py           write the files
    .venv/bin/python spec/vectors/generate.py --check   write nothing; exit 1 if a file
                                                        differs from what would be written

Each case is compiled with and without its debug section, both files are verified and
stepped on the VM (vm/drive.py), and the source is run on the AST interpreter (unless
the script loses the line after instruction counts, which only the VM counts), each run
on a fresh scripted device. All runs must agree (the stripped file knows no fault line), and agree
with what the case expects (its variables, status, fault line and trace, worked out
from the spec; see cases.py and oracle.py). If any case fails, no file is written.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from cases import Case, TraceItem, all_cases
from files import FileCase, all_file_cases

from rl1.compiler.analysis import analyze
from rl1.compiler.backend.driver import compile_text
from rl1.compiler.files import write_atomically
from rl1.compiler.ils.asm import AsmError, assemble
from rl1.compiler.interpreter import interpret
from rl1.vm import ilc
from rl1.vm.drive import drive
from rl1.vm.faults import FaultKind, RunResult
from rl1.vm.hardware import Blocking
from rl1.vm.language import VARIABLES
from rl1.vm.machine import Machine
from rl1.vm.scripted import ScriptedDevice, parse_script
from rl1.vm.verifier import VerifyError, verify

HERE = Path(__file__).resolve().parent
FORMAT = 3  # the version of the vector format (README.md); a change of layout bumps it
EXIT_STATUS = {kind.code: kind.exit_status for kind in FaultKind} | {"ok": 0}

Record = tuple[int, str, tuple[int, ...], tuple[int, ...]]  # time, call, args, result


@dataclass(frozen=True)
class Outcome:
    """How a run ended, in the terms a vector records."""

    status: str  # "ok" or the fault's code
    fault_line: int | None
    variables: tuple[int, ...]
    trace: tuple[Record, ...]
    executed: int | None = None  # instructions the VM ran; None for the interpreter


class VectorError(Exception):
    """A case that cannot become a vector: it does not compile, or a run disagrees."""


def _outcome(result: RunResult, device: ScriptedDevice, executed: int | None = None
             ) -> Outcome:
    fault = result.fault
    trace = tuple((entry.time, entry.call, entry.args, entry.result or ())
                  for entry in device.trace)
    if fault is None:
        return Outcome("ok", None, result.variables, trace, executed)
    return Outcome(fault.kind.code, fault.line, result.variables, trace, executed)


def run_vm(data: bytes, sensors: Mapping[str, Any], budget: int,
           machine: type[Machine] = Machine) -> Outcome:
    """Verify an .ilc file and step it on the VM (or on `machine`, a variant of it) with
    the sensor script."""
    device = ScriptedDevice(parse_script(dict(sensors), "sensors"))
    vm = machine(verify(data), Blocking(device), budget)
    return _outcome(drive(vm, device), device, vm.executed)


def interpretable(sensors: Mapping[str, Any]) -> bool:
    """Whether the interpreter can run with the script: no loss after an instruction."""
    return not parse_script(dict(sensors), "sensors").instruction_losses


def run_interpreter(source: str, sensors: Mapping[str, Any], budget: int) -> Outcome:
    """Run the source on the AST interpreter with the sensor script."""
    device = ScriptedDevice(parse_script(dict(sensors), "sensors"))
    return _outcome(interpret(analyze(source).program, device, budget), device)


def compile_both(case: Case) -> tuple[bytes, bytes]:
    """The case's .ilc file with its debug section, and without; for intermediate code
    written by hand, the assembled file and the same stripped."""
    if case.language == "ils":
        try:
            # the digest of the text itself, which a file of format 1.1 or newer carries
            digest = f'.digest "{ilc.source_digest(case.source).hex()}"\n'
            full = assemble(f".source {json.dumps(source_name(case))}\n{digest}.line 1\n"
                            + case.source)
        except AsmError as error:
            raise VectorError(f"{case.name}: the .ils text does not assemble: {error}") from None
        return full, ilc.encode(ilc.strip_debug(ilc.decode(full)))
    files = []
    for strip in (False, True):
        compilation = compile_text(case.source, source_name(case), strip_debug=strip,
                                   level=case.level)
        if compilation.output is None:
            errors = "; ".join(f"line {d.span.line}: {d.code} {d.message}"
                               for d in compilation.diagnostics if d.is_error)
            raise VectorError(f"{case.name}: the source does not compile: {errors}")
        files.append(compilation.output)
    return files[0], files[1]


def source_name(case: Case) -> str:
    return case.name + (".ils" if case.language == "ils" else ".rob")


def difference(expected: Outcome, actual: Outcome) -> str | None:
    """What first differs between two outcomes, for a person; None if nothing does."""
    if (expected.status, expected.fault_line) != (actual.status, actual.fault_line):
        return (f"status {actual.status} at line {actual.fault_line}, expected "
                f"{expected.status} at line {expected.fault_line}")
    wrong = [f"{name}={got} (expected {want})" for name, want, got
             in zip(VARIABLES, expected.variables, actual.variables, strict=True)
             if want != got]
    if wrong:
        return "variables " + ", ".join(wrong)
    for index, (want, got) in enumerate(zip(expected.trace, actual.trace, strict=False)):
        if want != got:
            return f"trace entry {index} is {got}, expected {want}"
    if len(expected.trace) != len(actual.trace):
        return f"the trace has {len(actual.trace)} entries, expected {len(expected.trace)}"
    if None not in (expected.executed, actual.executed) and expected.executed != actual.executed:
        return f"{actual.executed} instructions executed, expected {expected.executed}"
    return None


def _check_expectations(case: Case, outcome: Outcome) -> None:
    unknown = set(case.variables) - set(VARIABLES)
    if unknown:
        raise VectorError(f"{case.name}: the case names no variable {sorted(unknown)}")
    expected = Outcome(case.status, case.fault_line or None,
                       tuple(case.variables.get(name, 0) for name in VARIABLES), (),
                       case.executed)
    problem = difference(expected, replace(outcome, trace=()))
    if problem is None and case.trace is not None:
        problem = _trace_difference(case.trace, outcome.trace)
    if problem is not None:
        raise VectorError(f"{case.name}: the run gives {problem}, not what the spec says")


def _trace_difference(expected: Sequence[TraceItem], trace: Sequence[Record]) -> str | None:
    for index, ((time, call, args), (got_time, got_call, got_args, _)) in enumerate(
            zip(expected, trace, strict=False)):
        if (call, args) != (got_call, got_args) or time not in (None, got_time):
            return (f"trace entry {index} {got_time} {got_call} {list(got_args)}, expected "
                    f"{'-' if time is None else time} {call} {list(args)}")
    if len(expected) != len(trace):
        return f"a trace of {len(trace)} entries, expected {len(expected)}"
    return None


def build(case: Case) -> dict[str, Any]:
    """The vector of one case, after every run agrees."""
    if not (case.source.isascii() and json.dumps(dict(case.sensors)).isascii()):
        raise VectorError(f"{case.name}: vectors hold ASCII text only (README.md)")
    full, stripped = compile_both(case)
    outcome = run_vm(full, case.sensors, case.budget)
    others = {
        "the VM on the stripped file": (run_vm(stripped, case.sensors, case.budget),
                                        replace(outcome, fault_line=None)),
    }
    if case.language == "rl1" and interpretable(case.sensors):
        others["the AST interpreter"] = (
            run_interpreter(case.source, case.sensors, case.budget), outcome)
    for engine, (other, reference) in others.items():
        problem = difference(reference, other)
        if problem is not None:
            raise VectorError(f"{case.name}: {engine} disagrees with the VM: {problem}")
    _check_expectations(case, outcome)
    return {
        "name": case.name,
        "covers": case.covers,
        "source_name": source_name(case),
        "source": case.source,
        "sensors": dict(case.sensors),
        "budget": case.budget,
        "ilc": full.hex(),
        "ilc_stripped": stripped.hex(),
        "status": outcome.status,
        "exit_status": EXIT_STATUS[outcome.status],
        "fault_line": outcome.fault_line or 0,
        "executed": outcome.executed,
        "variables": list(outcome.variables),
        "trace": [{"time": time, "call": call, "args": list(args), "result": list(result)}
                  for time, call, args, result in outcome.trace],
    }


def render_group(group: str, vectors: list[dict[str, Any]]) -> str:
    """A group file: one field of a vector per line, one trace entry per line."""
    def field(key: str, value: Any) -> str:
        if key == "trace" and value:
            entries = ",\n".join("        " + json.dumps(entry) for entry in value)
            return f'      "{key}": [\n{entries}\n      ]'
        return f'      "{key}": {json.dumps(value)}'

    bodies = ["    {\n" + ",\n".join(field(key, value) for key, value in vector.items())
              + "\n    }" for vector in vectors]
    text = (f'{{\n  "format": {FORMAT},\n  "group": {json.dumps(group)},\n  "vectors": [\n'
            + ",\n".join(bodies) + "\n  ]\n}\n")
    assert json.loads(text) == {"format": FORMAT, "group": group, "vectors": vectors}
    # The README promises a C reader these three escapes and no other.
    assert text.isascii() and re.fullmatch(r'(?:[^\\]|\\[n"\\])*', text, re.DOTALL)
    return text


# What the message of a refusal by each rule of spec/ilc.md section 10 says: how the
# generator knows which rule refused a file (the C loader reports the rule's number).
RULE_MESSAGES = {
    1: "truncated|not an .ilc file", 2: "format version", 3: "truncated", 4: "header size",
    5: "section must be", 6: "truncated: the header's section sizes", 7: "unexpected bytes",
    8: "CRC-32 mismatch", 9: "required flag", 10: "points at code offset",
    11: "unknown feature bits", 12: "debug|line entry (repeats|\\(offset)|UTF-8|left over",
    13: "unknown opcode|an instruction of format", 14: "needs \\d+ bytes",
    15: "variable index|argument mask|out of range",
    16: "needs the device feature", 17: "jump target", 18: "handler :\\d+ at code offset",
    19: "line entry for code offset",
}


def build_file(case: FileCase) -> dict[str, Any]:
    """The verifier vector of one file, after the verifier does what the case says."""
    try:
        verify(case.data)
    except VerifyError as error:
        rule = case.rule
        if rule is None or error.offset != case.offset or not re.search(
                RULE_MESSAGES[rule], error.message):
            raise VectorError(f"{case.name}: refused at {error.offset} ({error.message}), "
                              f"expected rule {rule} at {case.offset}") from None
        return case.vector()
    if case.rule is not None:
        raise VectorError(f"{case.name}: accepted, expected rule {case.rule} at {case.offset}")
    return case.vector()


def _word(call: str) -> str:
    """A call's name as one word of the text form: "CAM A" is "CAM_A"."""
    return call.replace(" ", "_")


def _sensor_lines(sensors: Mapping[str, Any]) -> list[str]:
    """The sensor script as lines of the text form, each list in its order."""
    fields = {"IMG": ("area", "x", "y", "z"), "KYO": ("centre", "right", "left"),
              "FZI": ("s", "t")}
    lines = []
    for key, readings in sensors.items():
        if key in fields:
            lines += [f"sensor {key} " + " ".join(str(r[f]) for f in fields[key])
                      for r in readings]
        elif key in ("CAM R", "ULT A", "ULT B", "ULT C", "ULT D"):
            lines += [f"sensor {_word(key)} {value}" for value in readings]
        elif key == "INP":
            lines += [f"sensor INP {port} {value}" for port, values in readings.items()
                      for value in values]
        elif key == "line_lost":
            for loss in readings:
                if "during" in loss:
                    lines.append(f"loss during {loss['during']} {loss['nth']} "
                                 f"{loss.get('after', 1)}")
                else:
                    (kind, value), = loss.items()
                    lines.append(f"loss {kind} {value}")
        elif key == "fail":
            lines += [f"fail {_word(call)} {nth}" for call, nth in readings.items()]
        elif key == "stop_fails" and readings:
            lines.append("stop_fails")
        elif key == "after_last":
            lines.append(f"after_last {readings}")
    return lines


def render_text(group: str, vectors: list[dict[str, Any]]) -> str:
    """GROUP.txt: the same vectors as GROUP.json, a line per fact (README.md, "The text
    form"), for a C runner without a JSON reader."""
    lines = [f"rl1-vectors {FORMAT} {group}"]
    for vector in vectors:
        lines += [f"vector {vector['name']}", f"budget {vector['budget']}",
                  f"ilc {vector['ilc']}", f"ilc_stripped {vector['ilc_stripped']}",
                  *_sensor_lines(vector["sensors"]),
                  f"status {vector['status']} {vector['exit_status']} {vector['fault_line']}",
                  f"executed {vector['executed']}",
                  "variables " + " ".join(map(str, vector["variables"]))]
        lines += [f"trace {e['time']} {_word(e['call'])} {len(e['args'])} "
                  + " ".join(map(str, [*e["args"], len(e["result"]), *e["result"]]))
                  for e in vector["trace"]]
        lines.append("end")
    return "\n".join(lines) + "\n"


def render_files_text(vectors: list[dict[str, Any]]) -> str:
    """verifier.txt: a line per file: name, hex, then accepted, or refused, rule, offset."""
    lines = [f"rl1-vectors {FORMAT} verifier"]
    lines += [f"file {v['name']} {v['ilc']} "
              + ("accepted" if v["accepted"] else f"refused {v['rule']} {v['offset']}")
              for v in vectors]
    return "\n".join(lines) + "\n"


def render_files(vectors: list[dict[str, Any]]) -> str:
    """verifier.json: one file vector a line."""
    lines = ",\n".join("    " + json.dumps(vector) for vector in vectors)
    text = (f'{{\n  "format": {FORMAT},\n  "group": "verifier",\n  "files": [\n{lines}\n'
            "  ]\n}\n")
    assert text.isascii() and json.loads(text)["files"] == vectors
    return text


def generate(cases: Sequence[Case], file_cases: Sequence[FileCase] = ()) -> dict[Path, str]:
    """The text of every vector file, by path; VectorError if a case fails. The verifier
    vectors are written only when `file_cases` are given."""
    groups: dict[str, list[dict[str, Any]]] = {}
    names: set[str] = set()
    for case in cases:
        if case.name in names:
            raise VectorError(f"{case.name}: two cases have this name")
        names.add(case.name)
        groups.setdefault(case.group, []).append(build(case))
    files = {}
    for group, vectors in groups.items():
        files[HERE / f"{group}.json"] = render_group(group, vectors)
        files[HERE / f"{group}.txt"] = render_text(group, vectors)
    if file_cases:
        file_vectors = [build_file(case) for case in file_cases]
        files[HERE / "verifier.json"] = render_files(file_vectors)
        files[HERE / "verifier.txt"] = render_files_text(file_vectors)
    return files


def stale_files(files: Mapping[Path, str]) -> list[str]:
    """The vector files on disk that differ from `files`, are missing, or are not made
    by the generator at all."""
    stale = []
    for path in sorted({*files, *HERE.glob("*.json"), *HERE.glob("*.txt")}):
        want = files.get(path)
        have = path.read_text(encoding="utf-8") if path.exists() else None
        if want != have:
            reason = ("missing" if have is None else "not made by the generator"
                      if want is None else "out of date")
            stale.append(f"{path.name}: {reason}")
    return stale


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 if a vector file is out of date")
    arguments = parser.parse_args(argv)
    cases = all_cases()
    try:
        files = generate(cases, all_file_cases())
    except VectorError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    if arguments.check:
        stale = stale_files(files)
        for line in stale:
            print(line)
        if stale:
            print("run .venv/bin/python spec/vectors/generate.py to bring them up to date",
                  file=sys.stderr)
        return 1 if stale else 0
    for path, text in files.items():
        write_atomically(path, text.encode("ascii"))
    print(f"wrote {len(cases)} vectors in {len(files)} files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
