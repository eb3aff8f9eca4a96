"""`rl1c fuzz`: the built-in engines agree, an `exec:` engine speaks the protocol of
spec/optimization.md section 5, and a planted bug is found, shrunk and written down."""

from __future__ import annotations

import contextlib
import json
import os
import shlex
import shutil
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import find, given
from hypothesis import strategies as st
from support import ROOT
from support.cli import rl1c
from support.planted import BROKEN_VM, BrokenShift
from support.processes import ends_within

from rl1.compiler import differential, fuzz
from rl1.compiler.differential import (
    Engine,
    Observation,
    VmEngine,
    differences,
    engine_named,
    judge,
    printed_run,
)
from rl1.compiler.frontend.source import split_lines
from rl1.compiler.strategies import Run

RL1C = shlex.quote(str(Path(sys.executable).with_name("rl1c")))


def test_the_built_in_engines_agree_and_the_summary_says_so() -> None:
    result = rl1c("fuzz", "--count", "25", "--seed", "5")
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("fuzz: 25 programs in ")
    assert "engines ast, vm-O0, vm-O1, vm-O2; seed 5: all agreed" in result.stdout


def test_a_long_campaign_is_many_searches_with_the_same_programs_for_a_seed(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # Each Hypothesis search keeps what it learnt of every run until it ends (a campaign
    # of 50,000 in one search grew past 10 GB), so a campaign is searches of BATCH runs.
    monkeypatch.setattr(fuzz, "BATCH", 4)
    engines = [engine_named("ast"), engine_named("vm-O0")]
    sources: list[list[str]] = [[], []]
    searches: list[int] = []

    def counted_find(*args: object, **kwargs: object) -> object:
        searches.append(1)
        return find(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(fuzz, "find", counted_find)
    for seen in sources:
        def judged(case: Run, *args: object, seen: list[str] = seen) -> object:
            seen.append(case.source)
            return judge(case, *args)  # type: ignore[arg-type]

        monkeypatch.setattr(fuzz, "judge", judged)
        outcome = fuzz.campaign([e for e in engines if e is not None], 20_000, count=10,
                                seconds=None, seed=7, progress=lambda *_: None)
        assert outcome.programs == 10 and outcome.finding is None
    assert len(searches) == 2 * 3  # 4 + 4 + 2 programs, twice
    assert sources[0] == sources[1] and len(sources[0]) == 10


class _CrashesOnLess:
    """An engine whose compiler fails on any program with a `<` (a shift or a branch),
    as the optimizer once failed on a line map: a crash is a finding, not the end of
    the campaign."""

    name = "crashes"
    level = None

    def run(self, case: Run, budget: int) -> Observation:
        if "<" in case.source:
            raise ValueError("line entry (10, 5): lines must not decrease")
        return engine_named("ast").run(case, budget)  # type: ignore[union-attr]


def test_an_engine_that_crashes_is_a_finding_shrunk_like_a_disagreement(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 40)
    reference = engine_named("ast")
    assert reference is not None
    outcome = fuzz.campaign([reference, _CrashesOnLess()], 20_000, count=300,
                            seconds=None, seed=3, progress=lambda *_: None)
    assert outcome.finding is not None
    assert "crashes: crashed: ValueError: line entry (10, 5): lines must not decrease" \
        in outcome.finding.verdict.problems
    assert len(split_lines(outcome.finding.case.source)) <= 5


class _Clock:
    """time.monotonic for fuzz.py on a machine so loaded that a minute passes between
    two runs."""

    def __init__(self) -> None:
        self.now = 0.0

    def monotonic(self) -> float:
        self.now += 60.0
        return self.now


def test_a_seed_gives_the_same_reproducer_however_long_the_runs_take(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Shrinking was bounded by 20 seconds: a loaded machine wrote a larger reproducer.
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 60)
    engines: list[Engine] = [VmEngine(0), BrokenShift()]
    folders = []
    for clock in (time, _Clock()):
        monkeypatch.setattr(fuzz, "time", clock)
        outcome = fuzz.campaign(engines, 20_000, count=300, seconds=None, seed=1,
                                progress=lambda *_: None)
        assert outcome.finding is not None
        out = tmp_path / type(clock).__name__
        folders.append(Path(fuzz.write_reproducer(str(out), outcome.finding, engines,
                                                  20_000).folder))
    made, loaded = ({path.name: path.read_bytes() for path in folder.iterdir()}
                    for folder in folders)
    assert made == loaded and "program.rob" in made


def test_rl1c_run_itself_is_an_exec_engine_as_the_spec_shows(tmp_path: Path) -> None:
    command = f"exec:{RL1C} run {{ilc}} --sensors {{sensors}} --budget {{budget}} --format json"
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", command, "--count", "4",
                  "--seed", "2", "--out", str(tmp_path))
    assert result.exit_code == 0, result.output
    assert "all agreed" in result.stdout


def test_a_planted_shift_bug_is_found_and_shrunk_to_a_few_lines(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Few runs of Hypothesis' shrinking; deleting lines does the rest.
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 40)
    out = tmp_path / "found"
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", BROKEN_VM, "--count", "300",
                  "--seed", "1", "--out", str(out))
    assert result.exit_code == 1, result.output
    assert "the engines disagree (reference: vm-O0)" in result.stdout
    found = out / "finding-1"
    program = (found / "program.rob").read_text(encoding="utf-8")
    # Which run disagrees first depends on Hypothesis' draws, which mix in the literals
    # of the modules the suite has loaded: a loop around the shift (5 lines) is as small
    # as some of those runs go.
    assert 1 <= len(split_lines(program)) <= 5, program
    assert "<" in program  # a left shift, by a negative count
    runs = [json.loads(path.read_text(encoding="utf-8")) for path in sorted(found.glob("run-*"))]
    assert len(runs) == 2 and runs[0]["variables"] != runs[1]["variables"]
    assert "variables: " in result.stdout and f"sh {found}/replay.sh" in result.stdout
    replay = (found / "replay.sh").read_text(encoding="utf-8")
    assert "rl1c run program-O0.ilc --sensors program.sensors.json" in replay
    assert {"program.sensors.json", "program-O0.ilc", "replay.sh"} <= {
        path.name for path in found.iterdir()}


@pytest.mark.usefixtures("quick_shrinking")
def test_an_engine_that_only_ever_says_watchdog_disagrees(tmp_path: Path) -> None:
    # When either run met the watchdog only the traces' shared prefix compared: an
    # engine printing {"status": {"code": "budget"}} agreed with 200 programs.
    lazy = shlex.quote(str(ROOT / "tests/support/engines/lazy.sh"))
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", f"exec:sh {lazy}", "--count",
                  "200", "--seed", "1", "--out", str(tmp_path))
    assert result.exit_code == 1, result.output
    assert "ending: ended normally / fault budget" in result.stdout
    assert "met the watchdog, where vm-O0 ended after" in result.stdout


def test_an_engine_that_prints_no_run_disagrees(tmp_path: Path) -> None:
    result = rl1c("fuzz", "--engine", "ast", "--engine", "exec:echo not json", "--count", "3",
                  "--seed", "4", "--out", str(tmp_path))
    assert result.exit_code == 1
    assert "ending: ended normally / fault no-run" in result.stdout \
        or "fault no-run" in result.stdout


@pytest.mark.parametrize(("args", "message"), [
    (["--engine", "vm-O7", "--engine", "ast"], "unknown engine 'vm-O7'"),
    (["--engine", "exec-O7:true", "--engine", "ast"], "unknown engine 'exec-O7:true'"),
    (["--engine", "ast"], "give at least two different engines"),
    (["--engine", "ast", "--engine", "ast"], "give at least two different engines"),
    (["--count", "5", "--time", "5"], "give --count or --time, not both"),
    (["--count", "0"], "argument --count: expected a whole number of at least 1"),
    (["--seed", "x"], "argument --seed: expected a whole number"),
])
def test_bad_options_are_usage_errors(args: list[str], message: str) -> None:
    result = rl1c("fuzz", *args)
    assert result.exit_code == 2
    assert message in result.stderr


def test_runs_are_compared_on_what_the_protocol_names_only() -> None:
    plain = Observation({"status": "ok", "variables": {}, "trace": [
        {"time": 0, "call": "MOV", "args": [3, 3]}]})  # the first form of the protocol
    annotated = Observation({
        "status": {"code": "ok", "exit_status": 0, "message": "the program ended",
                   "line": None},
        "variables": {}, "trace": [
            {"time": 0, "call": "LINE LOST", "args": [0], "line": 1, "during": None,
             "effect": "no-motion", "handler": None},
            {"time": 0, "call": "MOV", "args": [3, 3], "line": 2}]})
    assert differences(plain, annotated) == []
    moved = Observation({**annotated.document, "trace": [
        {"time": 0, "call": "MOV", "args": [3, 2], "line": 2}]})
    assert differences(annotated, moved) != []


# `exec:` engines: what they print, how long, and what they leave behind ------------------

CASE = Run("A=1\n", {})


def exec_run(command: str) -> Observation:
    engine = engine_named(f"exec:{command}")
    assert engine is not None
    return engine.run(CASE, 20_000)


def assert_disagrees(observation: Observation, code: str) -> None:
    reference = engine_named("ast")
    assert reference is not None
    assert observation.ending()["code"] == code  # type: ignore[index]
    assert differences(reference.run(CASE, 20_000), observation) != []


def test_an_engine_that_prints_too_much_is_stopped_and_disagrees() -> None:
    # Its whole output was read into memory: `exec:yes` reached 2.4 GB in its 10 s.
    limit = differential.EXEC_OUTPUT_LIMIT
    observation = exec_run(f"head -c {limit + 4 * 2**20} /dev/zero; sleep 30")
    assert_disagrees(observation, "too-much-output")
    assert f"more than {limit // 2**20} MiB" in observation.document["status"]["message"]


@pytest.mark.parametrize("printed", [
    '{"status":1,"variables":2,"trace":3}',
    '{"status":"ok","variables":{},"trace":[1]}',
    '{"status":"ok","variables":{},"trace":[{"time":0,"call":"MOV","args":3}]}',
    '{"status":"ok","variables":{},"trace":[{"time":0,"call":"IMG","args":[],"result":5}]}',
    '{"status":{"code":"ok","line":"x"},"variables":{},"trace":[]}',
    '{"status":"ok","variables":{"A":[]},"trace":[]}',
    "[" * 100_000,
    '"ok"',
    "\xff",
])
def test_output_that_is_no_run_disagrees(tmp_path: Path, printed: str) -> None:
    # Right keys, wrong types were an internal error of `rl1c fuzz` (exit 3).
    output = tmp_path / "output"
    output.write_bytes(printed.encode("latin-1"))
    observation = exec_run(f"cat {shlex.quote(str(output))}")
    assert_disagrees(observation, "no-run")


def test_a_number_too_long_for_python_is_read_as_any_wrong_value(tmp_path: Path) -> None:
    # Python refuses to convert more than 4,300 digits: an internal error.
    output = tmp_path / "output"
    output.write_text('{"status":"ok","variables":{"A":' + "7" * 5000 + '},"trace":[]}',
                      encoding="ascii")
    observation = exec_run(f"cat {shlex.quote(str(output))}")
    assert_disagrees(observation, "ok")


_json = st.recursive(st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False)
                     | st.text(),
                     lambda inner: st.lists(inner, max_size=4)
                     | st.dictionaries(st.text(max_size=8), inner, max_size=4), max_leaves=20)
_runs = st.fixed_dictionaries({"status": st.just("ok") | _json, "variables": _json,
                               "trace": st.lists(_json | st.fixed_dictionaries(
                                   {"time": _json, "call": _json, "args": _json}), max_size=3)})


@given(_json | _runs)
def test_whatever_an_engine_prints_is_a_run_or_no_run_and_compares(printed: object) -> None:
    document = printed_run(json.dumps(printed).encode(), b"")
    observation = Observation(document)
    reference = Observation({"status": "ok", "variables": {"A": 1}, "trace": []})
    assert document == printed or observation.ending() == {"code": "no-run", "line": None}
    differences(reference, observation)
    differences(observation, reference)


def test_a_timed_out_engine_leaves_no_process_behind(tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    # Only its shell was killed: its children ran on, orphaned.
    monkeypatch.setattr(differential, "EXEC_TIMEOUT", 1.0)
    pid_file = tmp_path / "pid"
    observation = exec_run(f"sleep 300 & echo $! > {pid_file}; sleep 300")
    pid = int(pid_file.read_text(encoding="ascii"))
    try:
        assert_disagrees(observation, "timeout")
        assert ends_within(pid, seconds=10.0)
    finally:
        if Path(f"/proc/{pid}").exists():
            os.kill(pid, 9)


@pytest.mark.skipif(shutil.which("setsid") is None, reason="the test starts setsid")
@pytest.mark.parametrize("ending", ["sleep 300", "exit 0"])
def test_an_engines_process_in_a_session_of_its_own_is_killed_too(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, ending: str) -> None:
    # Outside the process group that is killed: one left a program, for a campaign.
    monkeypatch.setattr(differential, "EXEC_TIMEOUT", 1.0)
    pid_file = tmp_path / "pid"
    exec_run(f"setsid sleep 300 > /dev/null 2>&1 & echo $! > {pid_file}; {ending}")
    pid = int(pid_file.read_text(encoding="ascii"))
    try:
        assert ends_within(pid, seconds=10.0), f"process {pid} outlived the engine"
    finally:
        with contextlib.suppress(ProcessLookupError):  # as it should be
            os.kill(pid, signal.SIGKILL)


@pytest.mark.skipif(not hasattr(os, "pidfd_open"), reason="the shell's end is seen by a pidfd")
@pytest.mark.parametrize("left", ["sleep 300 &", "setsid sleep 300 &"])
def test_an_engine_that_ended_is_its_run_though_a_process_it_left_holds_its_output(
        monkeypatch: pytest.MonkeyPatch, left: str) -> None:
    """Its output was read until its end of file, which a process it left running holds
    open: a command that had printed its run and ended was told to have run longer than
    the timeout."""
    monkeypatch.setattr(differential, "EXEC_TIMEOUT", 5.0)
    run = json.dumps({"status": "ok", "variables": {"A": 1}, "trace": []})
    observation = exec_run(f"{left} echo {shlex.quote(run)}")
    assert observation.document == json.loads(run)


def test_a_quoted_placeholder_never_runs_the_folder_name(tmp_path: Path) -> None:
    # shlex-quoted paths are literal bare, but inside double quotes the quote is a
    # character and a `$(...)` in the temporary folder's name ran.
    hostile = tmp_path / "tmp $(touch ran)"
    hostile.mkdir()
    done = subprocess.run([str(Path(sys.executable).with_name("rl1c")), "fuzz", "--engine",
                           "ast", "--engine", 'exec:cat "{ilc}" > /dev/null', "--count", "2",
                           "--out", str(tmp_path / "out")], capture_output=True, text=True,
                          env={**os.environ, "TMPDIR": str(hostile)}, cwd=tmp_path,
                          check=False)
    assert not (tmp_path / "ran").exists()
    assert done.returncode == 2, done.stderr
    assert "set TMPDIR to a folder" in done.stderr and "Traceback" not in done.stderr


# --out: a folder of its own for each finding ----------------------------------------------

NO_RUN = ("--engine", "ast", "--engine", "exec:echo not json", "--count", "3", "--seed", "4")


@pytest.fixture
def quick_shrinking(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 20)


@pytest.mark.usefixtures("quick_shrinking")
@pytest.mark.parametrize("there", ["a file", "a read-only file", "a link out", "a FIFO"])
def test_what_is_in_out_is_never_replaced_followed_or_written_into(tmp_path: Path,
                                                                   there: str) -> None:
    out, outside = tmp_path / "out", tmp_path / "outside.rob"
    out.mkdir()
    outside.write_text("mine\n", encoding="utf-8")
    existing = out / "program.rob"
    reader = None
    match there:
        case "a file" | "a read-only file":
            existing.write_text("mine\n", encoding="utf-8")
            if there == "a read-only file":
                existing.chmod(0o444)
        case "a link out":
            existing.symlink_to(outside)
        case "a FIFO":  # held open for reading, so that a write would not block
            os.mkfifo(existing)
            reader = os.open(existing, os.O_RDONLY | os.O_NONBLOCK)
    result = rl1c("fuzz", *NO_RUN, "--out", out)
    assert result.exit_code == 1, result.output
    assert outside.read_text(encoding="utf-8") == "mine\n"
    if reader is not None:
        assert stat.S_ISFIFO(existing.lstat().st_mode)
        assert os.read(reader, 4096) == b""  # no writer has written into it
        os.close(reader)
    elif there != "a link out":
        assert existing.read_text(encoding="utf-8") == "mine\n"
    program = (out / "finding-1" / "program.rob").read_text(encoding="utf-8")
    assert all(line in result.stdout for line in split_lines(program))
    assert f"reproducer: {out / 'finding-1'} " in result.stdout


@pytest.mark.usefixtures("quick_shrinking")
def test_each_finding_gets_a_folder_of_its_own(tmp_path: Path) -> None:
    out = tmp_path / "new" / "out"
    for _ in range(2):
        assert rl1c("fuzz", *NO_RUN, "--out", out).exit_code == 1
    assert sorted(path.name for path in out.iterdir()) == ["finding-1", "finding-2"]
    assert all((out / name / "replay.sh").is_file() for name in ("finding-1", "finding-2"))


@pytest.mark.usefixtures("quick_shrinking")
def test_replay_sh_judges_again_and_fails_while_the_engines_disagree(tmp_path: Path) -> None:
    # It printed each engine's run as JSON, compared nothing and exited 0.
    engine = tmp_path / "engine.sh"
    engine.write_text('echo \'{"status": {"code": "budget", "line": null}, "variables": {}, '
                      '"trace": []}\'\n', encoding="utf-8")
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine",
                  f"exec:sh {shlex.quote(str(engine))} {{ilc}} {{sensors}} {{budget}}",
                  "--count", "5", "--seed", "1", "--out", str(tmp_path / "out"))
    assert result.exit_code == 1, result.output
    replay = tmp_path / "out" / "finding-1" / "replay.sh"
    path = f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"

    def replayed() -> subprocess.CompletedProcess[str]:
        return subprocess.run(["sh", str(replay)], capture_output=True, text=True,
                              env={**os.environ, "PATH": path}, check=False)

    still = replayed()
    assert still.returncode == 1, still.stderr
    assert "replay: the engines still disagree (reference: vm-O0; budget 20000)" in still.stdout
    assert "ending: ended normally / fault budget" in still.stdout
    engine.write_text(f'exec {RL1C} run "$1" --sensors "$2" --budget "$3" --format json\n',
                      encoding="utf-8")  # the engine fixed
    fixed = replayed()
    assert fixed.returncode == 0, fixed.stdout + fixed.stderr
    assert fixed.stdout.startswith("replay: the engines agree now (engines vm-O0, exec:sh ")


def _reproducer(folder: Path) -> None:
    folder.mkdir()
    (folder / "program.rob").write_text("A=1\n", encoding="utf-8")
    (folder / "program.sensors.json").write_text("{}", encoding="utf-8")
    (folder / "engines.json").write_text('{"engines": ["ast", "vm-O0"], "budget": 9}',
                                         encoding="utf-8")


def test_a_sound_reproducer_replays_to_agreement(tmp_path: Path) -> None:
    _reproducer(tmp_path / "found")
    result = rl1c("fuzz", "--replay", tmp_path / "found")
    assert result.exit_code == 0, result.output
    assert "the engines agree now (engines ast, vm-O0; budget 9)" in result.stdout


@pytest.mark.parametrize(("file", "text", "message"), [
    (None, None, "cannot read the reproducer's file"),
    ("program.rob", "A=\n", "program.rob` is not valid: the checker finds errors in it"),
    ("program.sensors.json", "[", "program.sensors.json` is not valid: it is not JSON"),
    ("program.sensors.json", '{"IMG": 3}', "program.sensors.json` is not valid: "),
    ("engines.json", "{}", 'expected {"engines": [NAME, ...], "budget": N}'),
    ("engines.json", '{"engines": ["ast", "vm-O0"], "budget": 0}', "with N from 1 to"),
    ("engines.json", '{"engines": ["ast", "vm-O9"], "budget": 5}', "unknown engine 'vm-O9'"),
    ("engines.json", '{"engines": ["ast", 3], "budget": 5}', "unknown engine 3"),
    ("engines.json", '{"engines": ["ast"], "budget": 5}', "fewer than two engines"),
])
def test_a_reproducer_that_cannot_be_replayed_says_which_file_and_why(
        tmp_path: Path, file: str | None, text: str | None, message: str) -> None:
    folder = tmp_path / "found"
    _reproducer(folder)
    if file is None:
        (folder / "engines.json").unlink()
    else:
        (folder / file).write_text(text or "", encoding="utf-8")
    result = rl1c("fuzz", "--replay", folder)
    assert result.exit_code == 2, result.output
    assert message in result.stderr and "Traceback" not in result.output


def test_replay_takes_its_engines_from_the_reproducer(tmp_path: Path) -> None:
    result = rl1c("fuzz", "--replay", tmp_path, "--engine", "ast")
    assert result.exit_code == 2
    assert "--replay takes the engines and budget of the reproducer" in result.stderr


@pytest.mark.parametrize("out", ["a file", "a folder under a file", "a link to nothing"])
def test_an_out_that_is_no_folder_is_refused_before_the_campaign(tmp_path: Path,
                                                                 out: str) -> None:
    # A file ended in an internal error after the finding was shrunk, losing it.
    file = tmp_path / "file"
    file.write_text("", encoding="utf-8")
    (tmp_path / "link").symlink_to(tmp_path / "nothing")
    named = {"a file": file, "a folder under a file": file / "sub",
             "a link to nothing": tmp_path / "link"}[out]
    result = rl1c("fuzz", *NO_RUN, "--out", named)
    assert result.exit_code == 2
    assert "argument --out" in result.stderr and "is not a folder" in result.stderr
    assert result.stdout == ""


@pytest.mark.usefixtures("quick_shrinking")
def test_a_reproducer_that_cannot_be_written_leaves_the_finding_printed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def full_disk(*args: object, **kwargs: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(fuzz, "write_atomically", full_disk)
    result = rl1c("fuzz", *NO_RUN, "--out", tmp_path / "out")
    assert result.exit_code == 1
    assert "the smallest program found:" in result.stdout
    assert "cannot write the reproducer under" in result.stderr
    assert "No space left on device" in result.stderr and "Traceback" not in result.output


# Hypothesis, an optional part of rl1 -------------------------------------------------------

WITHOUT_HYPOTHESIS = """
import sys

class Hidden:
    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] == "hypothesis":
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)

sys.meta_path.insert(0, Hidden())
"""


def without_hypothesis(code: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", WITHOUT_HYPOTHESIS + code],
                          capture_output=True, text=True, check=False)


def test_rl1c_fuzz_without_hypothesis_says_what_to_install() -> None:
    done = without_hypothesis("from rl1.compiler.cli.main import rl1c\n"
                              "sys.argv = ['rl1c', 'fuzz', '--count', '1']\nrl1c()")
    assert done.returncode == 2
    assert "pip install 'rl1[fuzz]'" in done.stderr and "Traceback" not in done.stderr


def test_the_strategies_without_hypothesis_say_what_to_install() -> None:
    done = without_hypothesis("import rl1.compiler.strategies")
    assert done.returncode == 1
    assert "rl1.compiler.strategies generates programs with Hypothesis" in done.stderr
    assert "pip install 'rl1[fuzz]'" in done.stderr
