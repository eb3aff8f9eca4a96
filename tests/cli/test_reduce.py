"""Reducing a case (compiler/reduce.py) and `rl1c reduce`: every pass keeps the case
interesting, the result is the same from run to run and never larger, the original is
never touched, and hostile commands and files end with a message and a status."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import SAMPLE, SAMPLE_SENSORS
from support.cli import rl1c
from support.planted import BROKEN_VM, BrokenShift
from support.processes import ends_within

from rl1.compiler import fuzz
from rl1.compiler.analysis import analyze
from rl1.compiler.differential import Engine, VmEngine, judge
from rl1.compiler.reduce import Case, NotInteresting, reduce, smaller_numbers
from rl1.compiler.strategies import Run, checked_programs, sensor_scripts
from rl1.vm.sensor_script import decode_script

PYTHON = shlex.quote(sys.executable)
RL1C = str(Path(sys.executable).with_name("rl1c"))


TESTS = 2000  # the tests a reduction may run, far more than these take


def moves(case: Case) -> bool:
    """A planted interestingness: the checker accepts a program with a (MOV ...)."""
    return "(MOV" in case.source


# The passes --------------------------------------------------------------------------


def test_a_program_is_reduced_to_the_one_statement_that_matters() -> None:
    reduction = reduce(Case(SAMPLE.read_text(encoding="utf-8")), moves, max_tests=TESTS)
    # Deleting lines and statements leaves one (MOV 3,3), its operands made 0.
    assert reduction.case == Case("(MOV 0,0)\n")
    assert reduction.finished and reduction.tests < 100


def disagrees(case: Case) -> bool:
    """Interesting: the planted bug shows (vm-O0 and the broken VM disagree)."""
    engines: list[Engine] = [VmEngine(0), BrokenShift()]
    return bool(judge(Run(case.source, json.loads(case.script or "{}")), engines,
                      20_000).problems)


def test_terms_operands_and_hex_constants_shrink_towards_zero() -> None:
    # What `rl1c fuzz --seed 1` found against the broken VM of tests/support/broken_vm.py.
    reduction = reduce(Case("B=$0+$1<$FFFF\n"), disagrees, max_tests=TESTS)
    assert reduction.case.source == "B=1<-1\n"


def test_the_sensor_script_keeps_only_what_matters_with_its_numbers_made_small() -> None:
    script = SAMPLE_SENSORS.read_text(encoding="utf-8")

    def sees_far(case: Case) -> bool:  # an IMG reading whose area is over 100
        data = json.loads(case.script or "{}")
        return any(reading["area"] > 100 for reading in data.get("IMG", []))

    reduction = reduce(Case("(MOV 3,3)\n", script), sees_far, max_tests=TESTS)
    data = json.loads(reduction.case.script or "")
    assert list(data) == ["IMG"] and len(data["IMG"]) == 1
    reading = data["IMG"][0]
    # Halving stops at the first half that is not interesting: 101..200.
    assert (reading["x"], reading["y"], reading["z"]) == (0, 0, 0)
    assert 100 < reading["area"] <= 200
    assert reduction.case.script == '{\n  "IMG": [' + json.dumps(reading) + "]\n}\n"


def test_a_candidate_larger_than_the_original_is_never_tested() -> None:
    compact = '{"IMG":[{"area":1000,"x":0,"y":0,"z":0}]}'
    tested: list[Case] = []

    def sees_far(case: Case) -> bool:
        tested.append(case)
        readings = json.loads(case.script or "{}").get("IMG", [])
        return any(reading["area"] > 100 for reading in readings)

    original = Case("(MOV 0,0)\n", compact)
    reduction = reduce(original, sees_far, max_tests=TESTS)
    # Written one key a line, a smaller area is a longer script: left as it was.
    assert reduction.case == original
    assert len(tested) > 1 and all(case.size <= original.size for case in tested)


def test_a_script_nothing_needs_becomes_empty() -> None:
    reduction = reduce(Case("(MOV 3,3)\n", SAMPLE_SENSORS.read_text(encoding="utf-8")),
                       moves, max_tests=TESTS)
    assert reduction.case == Case("(MOV 0,0)\n", "{}\n")


def test_the_layout_is_the_formatters_when_it_stays_interesting() -> None:
    def spaced(case: Case) -> bool:
        return "(MOV" in case.source and "=" in case.source

    reduction = reduce(Case("A = 1 ;  (MOV  3 , 3) ' a comment\n"), spaced, max_tests=TESTS)
    assert reduction.case.source == "A=0; (MOV 0,0)\n"


def test_lines_keep_the_originals_line_ends() -> None:
    reduction = reduce(Case("A=1\r\n(MOV 3,3)\r\nB=2\r\n"), moves, max_tests=TESTS)
    assert reduction.case.source == "(MOV 0,0)\r\n"


def test_a_case_that_is_not_interesting_is_refused() -> None:
    with pytest.raises(NotInteresting):
        reduce(Case("(END)\n"), moves, max_tests=TESTS)


def test_the_tests_are_capped_and_the_smallest_so_far_is_kept() -> None:
    tested: list[Case] = []

    def counted(case: Case) -> bool:
        tested.append(case)
        return moves(case)

    reduction = reduce(Case(SAMPLE.read_text(encoding="utf-8")), counted, max_tests=5)
    assert not reduction.finished and reduction.tests == len(tested) == 5
    assert reduction.case == max((case for case in tested if moves(case)),
                                 key=tested.index)


def test_a_program_the_checker_accepts_stays_accepted() -> None:
    tested: list[str] = []

    def anything(case: Case) -> bool:
        tested.append(case.source)
        return True

    reduce(Case(SAMPLE.read_text(encoding="utf-8")), anything, max_tests=TESTS)
    assert tested and not any(analyze(source).has_errors for source in tested)


@given(st.integers(-2**17, 2**17))
def test_smaller_numbers_are_smaller(value: int) -> None:
    for number in smaller_numbers(value):
        assert (abs(number), number < 0) < (abs(value), value < 0)
    assert smaller_numbers(0) == []


@settings(max_examples=25, deadline=None)
@given(checked_programs(max_blocks=3), sensor_scripts(), st.data())
def test_the_result_is_interesting_no_larger_and_the_same_every_time(
        source: str, script: dict[str, object], data: st.DataObject) -> None:
    text = json.dumps(script)
    needle = data.draw(st.sampled_from(sorted(set(source.replace(" ", "")) - {"\n"})))

    def interesting(case: Case) -> bool:  # a character of the program, an IMG reading
        return needle in case.source and '"IMG"' in (case.script or "")

    first, second = (reduce(Case(source, text), interesting, max_tests=300)
                     for _ in range(2))
    assert first == second
    assert interesting(first.case) and first.case.size <= Case(source, text).size
    assert not analyze(first.case.source).has_errors
    decode_script((first.case.script or "").encode(), "script.json")


@settings(max_examples=25, deadline=None)
@given(checked_programs(max_blocks=3), sensor_scripts(), st.integers(2, 5))
def test_any_predicate_sees_only_well_formed_candidates_no_larger_than_the_original(
        source: str, script: dict[str, object], modulus: int) -> None:
    original = Case(source, json.dumps(script))
    tested: list[Case] = []

    def erratic(case: Case) -> bool:  # no rule at all: a hash of the candidate
        tested.append(case)
        digest = hashlib.sha256(f"{case.source}{case.script}".encode()).digest()
        return case == original or digest[0] % modulus == 0

    reduction = reduce(original, erratic, max_tests=200)
    assert erratic(reduction.case) and reduction.tests == len(tested) - 1
    for case in tested:
        assert case.size <= original.size and not analyze(case.source).has_errors
        decode_script((case.script or "").encode(), "script.json")


# rl1c reduce ---------------------------------------------------------------------------


@pytest.fixture
def sample(tmp_path: Path) -> tuple[Path, Path]:
    program, script = tmp_path / "sample.rob", tmp_path / "sample.sensors.json"
    program.write_bytes(SAMPLE.read_bytes())
    script.write_bytes(SAMPLE_SENSORS.read_bytes())
    return program, script


GREP = "grep -q '(MOV' sample.rob && grep -q IMG sample.sensors.json"


def test_rl1c_reduce_writes_the_result_beside_and_leaves_the_original(
        sample: tuple[Path, Path]) -> None:
    program, script = sample
    result = rl1c("reduce", program, "--sensors", script, "--interesting", GREP)
    assert result.exit_code == 0, result.output
    assert program.read_bytes() == SAMPLE.read_bytes()
    assert script.read_bytes() == SAMPLE_SENSORS.read_bytes()
    reduced = program.with_name("sample.reduced.rob")
    assert reduced.read_text(encoding="utf-8") == "(MOV 0,0)\n"
    assert json.loads(program.with_name("sample.sensors.reduced.json").read_bytes()) == {
        "IMG": [{"area": 0, "x": 0, "y": 0, "z": 0}]}
    assert result.stdout.startswith(
        f"reduced {program}: 43 lines, 754 bytes -> 1 line, 10 bytes\n"
        f"sensor script {script}: 27 lines, 1360 bytes -> 3 lines, 51 bytes\n")
    assert "rl1c reduce: lines: " in result.stderr  # progress, pass by pass


def test_rl1c_reduce_gives_the_same_bytes_every_time(sample: tuple[Path, Path]) -> None:
    # A command whose answer depends on more than a grep: the first IMG reading's area.
    program, script = sample
    wide = (f"{PYTHON} -c \"import json,sys; sys.exit(json.load(open('sample.sensors.json'))"
            "['IMG'][0]['area'] < 50)\" && grep -q '(MOV' sample.rob")
    made = []
    for name, hash_seed in (("first.rob", "1"), ("second.rob", "2")):  # two processes
        out = program.with_name(name)
        subprocess.run([RL1C, "reduce", str(program), "--sensors", str(script),
                        "--interesting", wide, "--out", str(out), "--sensors-out",
                        str(out.with_suffix(".json"))], check=True, capture_output=True,
                       env={**os.environ, "PYTHONHASHSEED": hash_seed})
        made.append((out.read_bytes(), out.with_suffix(".json").read_bytes()))
    assert made[0] == made[1]
    assert json.loads(made[0][1])["IMG"][0]["area"] >= 50


def test_out_may_name_the_original(sample: tuple[Path, Path]) -> None:
    program, _ = sample
    result = rl1c("reduce", program, "--interesting", "grep -q '(MOV' sample.rob",
                  "--out", program)
    assert result.exit_code == 0, result.output
    assert program.read_bytes() == b"(MOV 0,0)\n"


def test_a_command_that_fails_on_the_original_says_so(sample: tuple[Path, Path]) -> None:
    program, script = sample
    result = rl1c("reduce", program, "--sensors", script, "--interesting",
                  "echo no such thing; exit 3")
    assert result.exit_code == 1
    assert result.stderr == (
        "rl1c reduce: error: the original is not interesting: `echo no such thing; exit 3`"
        " exited with status 3 and printed, at the end: no such thing; the command must "
        "exit 0 on the original (it runs in a new temporary folder holding sample.rob and "
        "sample.sensors.json)\n")
    assert not program.with_name("sample.reduced.rob").exists()


def test_a_command_that_hangs_is_stopped_at_the_timeout(sample: tuple[Path, Path]) -> None:
    program, _ = sample
    started = time.monotonic()
    result = rl1c("reduce", program, "--interesting", "sleep 60 & sleep 60", "--timeout", "1")
    assert time.monotonic() - started < 30
    assert result.exit_code == 1
    assert "`sleep 60 & sleep 60` ran longer than 1 s (--timeout)" in result.stderr


@pytest.mark.skipif(not sys.platform.startswith("linux") or shutil.which("setsid") is None,
                    reason="a child subreaper is Linux's, and the test starts setsid")
@pytest.mark.parametrize("ending", ["sleep 60", "exit 1"])
def test_a_process_the_command_started_in_a_session_of_its_own_is_killed_too(
        sample: tuple[Path, Path], tmp_path: Path, ending: str) -> None:
    # Outside the process group, which the timeout kills; as each test runs the command
    # again, such processes would pile up for the whole reduction.
    program, _ = sample
    pid_file = tmp_path / "pid"
    command = f"setsid sleep 300 & echo $! > {shlex.quote(str(pid_file))}; {ending}"
    result = rl1c("reduce", program, "--interesting", command, "--timeout", "1")
    assert result.exit_code == 1
    orphan = int(pid_file.read_text())
    try:
        assert ends_within(orphan, 10), f"process {orphan}, in a session of its own, outlived" \
            " the command"
    finally:
        with contextlib.suppress(ProcessLookupError):  # as it should be
            os.kill(orphan, signal.SIGKILL)


def test_a_command_that_prints_megabytes_keeps_only_the_end(
        sample: tuple[Path, Path]) -> None:
    program, _ = sample
    result = rl1c("reduce", program, "--interesting",
                  "head -c 30000000 /dev/zero | tr '\\0' y; echo; echo the end; exit 1")
    assert result.exit_code == 1
    assert "printed, at the end: the end;" in result.stderr and len(result.stderr) < 1000


@pytest.mark.parametrize("args", [
    ("missing.rob", "--interesting", "true"),
    (".", "--interesting", "true"),
    (str(SAMPLE), "--sensors", "missing.json", "--interesting", "true"),
])
def test_an_unreadable_file_is_a_message_and_status_2(args: tuple[str, ...]) -> None:
    result = rl1c("reduce", *args)
    assert result.exit_code == 2
    assert "error[E0100]: cannot read the " in result.stderr
    assert "Traceback" not in result.output


def test_a_script_that_is_not_text_is_refused(tmp_path: Path) -> None:
    script = tmp_path / "s.json"
    script.write_bytes(b"\xff\xfe{}")
    result = rl1c("reduce", SAMPLE, "--sensors", script, "--interesting", "true")
    assert result.exit_code == 2
    assert "is not valid: it is not UTF-8 text (byte 0)" in result.stderr


@pytest.mark.parametrize(("args", "said"), [
    ((), "give --interesting CMD or --engine NAME"),
    (("--interesting", "true", "--engine", "vm-O0"), "give --interesting CMD or --engine"),
    (("--engine", "vm-O0"), "give at least two different engines"),
    (("--engine", "vm-O0", "--engine", "vm-O9"), "unknown engine 'vm-O9'"),
    (("--interesting", "true", "--max-tests", "0"), "expected a whole number of at least 1"),
])
def test_usage_problems(args: tuple[str, ...], said: str) -> None:
    result = rl1c("reduce", SAMPLE, *args)
    assert result.exit_code == 2 and said in result.stderr


def test_a_script_nested_too_deeply_is_left_as_it_is(sample: tuple[Path, Path]) -> None:
    program, script = sample
    deep = '{"a":' * 990 + "1" + "}" * 990
    script.write_text(deep, encoding="utf-8")
    result = rl1c("reduce", program, "--sensors", script, "--interesting",
                  "grep -q '(MOV' sample.rob && grep -q 1 sample.sensors.json")
    assert result.exit_code == 0, result.output
    figures = f"1 line, {len(deep)} bytes"
    assert f"sensor script {script}: {figures} -> {figures}\n" in result.stdout
    assert script.read_text(encoding="utf-8") == deep


def test_an_output_that_cannot_be_written_is_refused_before_reducing(
        sample: tuple[Path, Path]) -> None:
    program, _ = sample
    for out, said in ((program.parent, "it is a folder; name a file"),
                      (program.parent / "none" / "x.rob", "there is no folder ")):
        result = rl1c("reduce", program, "--interesting", "true", "--out", out)
        assert result.exit_code == 2 and f"error: argument --out: {out}: {said}" \
            in result.stderr
        assert "rl1c reduce: lines" not in result.stderr


def test_an_output_onto_another_input_or_nowhere_is_refused_before_reducing(
        sample: tuple[Path, Path]) -> None:
    program, script = sample
    read_only = program.with_name("kept.rob")
    read_only.write_bytes(b"")
    read_only.chmod(0o444)
    for args, said in (
            (("--out", script), f"argument --out: {script}: it is the sensor script"),
            (("--sensors-out", program), f"argument --sensors-out: {program}: it is the "
                                         "program"),
            (("--out", "x.rob", "--sensors-out", "x.rob"), "argument --out: x.rob: it is "
                                                           "--sensors-out"),
            (("--out", "-"), "argument --out: the result is written to a file"),
            (("--out", read_only), f"argument --out: {read_only}: it is read-only")):
        result = rl1c("reduce", program, "--sensors", script, "--interesting", GREP, *args)
        assert result.exit_code == 2 and said in result.stderr, (args, result.output)
        assert "rl1c reduce: lines" not in result.stderr  # refused before any test
    assert program.read_bytes() == SAMPLE.read_bytes()
    assert script.read_bytes() == SAMPLE_SENSORS.read_bytes()
    assert not Path("-").exists()


@pytest.mark.parametrize("command", ["", "   "])
def test_an_empty_command_is_refused(command: str) -> None:
    result = rl1c("reduce", SAMPLE, "--interesting", command)
    assert result.exit_code == 2 and "the command is empty" in result.stderr


def test_engines_that_agree_leave_nothing_to_reduce() -> None:
    result = rl1c("reduce", SAMPLE, "--sensors", SAMPLE_SENSORS, "--engine", "vm-O0",
                  "--engine", "vm-O2")
    assert result.exit_code == 1
    assert f"the engines agree on {SAMPLE}: nothing to reduce" in result.stderr


def test_rl1c_fuzz_reduces_its_finding_with_these_passes(monkeypatch: pytest.MonkeyPatch
                                                        ) -> None:
    # Hypothesis' shrinking for 40 runs, then lines and statements deleted, left
    # ` j=$0011\t<$FA8D^ $0100+t +136&$41c` and a script of seven keys.
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 40)
    engines: list[Engine] = [VmEngine(0), BrokenShift()]
    outcome = fuzz.campaign(engines, 20_000, count=300, seconds=None, seed=1,
                            progress=lambda *_: None)
    assert outcome.finding is not None
    assert re.fullmatch(r"[A-Za-z@]=1<-1(\r\n|\r|\n)", outcome.finding.case.source)
    assert outcome.finding.case.script == {}


def test_a_fuzz_finding_of_a_planted_bug_is_reduced_with_its_engines(tmp_path: Path) -> None:
    # What `rl1c fuzz --seed 1` against broken_vm.py wrote (its shrinker had made it).
    program, script = tmp_path / "program.rob", tmp_path / "program.sensors.json"
    program.write_text("B=$0+$1<$FFFF\n", encoding="utf-8")
    script.write_text(json.dumps({
        "IMG": [{"area": 1000, "x": 128, "y": 100, "z": 0}],
        "KYO": [{"centre": 0, "right": 0, "left": 0}] * 2, "ULT A": [0], "ULT C": [0],
        "CAM R": [0, 496, 205], "FZI": [{"s": 1200, "t": 713}],
        "line_lost": [{"time": 258}], "after_last": "repeat"}, indent=2), encoding="utf-8")
    result = rl1c("reduce", program, "--sensors", script, "--engine", "vm-O0", "--engine",
                  BROKEN_VM)
    assert result.exit_code == 0, result.output
    assert program.with_name("program.reduced.rob").read_text(encoding="utf-8") == "B=1<-1\n"
    assert program.with_name("program.sensors.reduced.json").read_text(
        encoding="utf-8") == "{}\n"


def test_ctrl_c_keeps_the_smallest_so_far(sample: tuple[Path, Path], tmp_path: Path) -> None:
    program, _ = sample
    said, holding = tmp_path / "stderr.txt", tmp_path / "holding"
    # Every test after the first progress line holds (until rl1c ends it), so that the
    # signal always lands mid-reduction, whatever the machine's speed.
    held = (f"if grep -q '^rl1c reduce: ' {shlex.quote(str(said))}; then "
            f"touch {shlex.quote(str(holding))}; sleep 60; fi; grep -q '(MOV' sample.rob")
    with open(said, "w") as stderr:
        process = subprocess.Popen([RL1C, "reduce", str(program), "--interesting", held],
                                   stdout=subprocess.PIPE, stderr=stderr, text=True)
    try:
        deadline = time.monotonic() + 60
        while not holding.exists():
            assert process.poll() is None, f"it ended before a test held: {said.read_text()}"
            assert time.monotonic() < deadline, said.read_text()
            time.sleep(0.05)
        first = said.read_text().splitlines()[0]  # a pass made it smaller
        assert first.startswith("rl1c reduce: lines: "), first
        process.send_signal(signal.SIGINT)
        stdout, _ = process.communicate(timeout=60)
    finally:
        process.kill()
        process.wait()
    assert process.returncode == 130, said.read_text()
    assert "interrupted (Ctrl-C) with the smallest so far" in stdout
    reduced = program.with_name("sample.reduced.rob").read_text(encoding="utf-8")
    assert "(MOV" in reduced and len(reduced) < len(SAMPLE.read_text(encoding="utf-8"))
    assert program.read_bytes() == SAMPLE.read_bytes()
