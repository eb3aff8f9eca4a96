"""Batch engines of `rl1c fuzz` (`exec-batch:COMMAND`): one process answering one job after
another, `rl1c run --batch` as the reference, and engines that die, lie or hang."""

from __future__ import annotations

import base64
import io
import json
import os
import shlex
import sys
import time
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support import ROOT
from support.cli import rl1c
from support.processes import ends_within

from rl1.compiler import differential, fuzz
from rl1.compiler.cli import run_batch
from rl1.compiler.differential import BatchEngine, VmEngine, compiled, engine_named, judge
from rl1.compiler.strategies import Run
from rl1.vm.defaults import DEFAULT_TIME_LIMIT_MS

pytestmark = pytest.mark.slow  # engine processes

RL1C = shlex.quote(str(Path(sys.executable).with_name("rl1c")))
REFERENCE = f"exec-batch:{RL1C} run --batch"
CASE = Run("A=1; B=(ULT A)\n(MOV 3,3); (TIM 20); (HLD); (END)\n", {"ULT A": [17]})


def _batch(command: str) -> BatchEngine:
    engine = engine_named(f"exec-batch:{command}")
    assert isinstance(engine, BatchEngine)
    return engine


def _job(source: str, script: object, budget: int = 20_000) -> str:
    return json.dumps({"ilc": base64.b64encode(compiled(source, 0)).decode("ascii"),
                       "sensors": script, "budget": budget})


def test_rl1c_run_batch_answers_each_job_as_rl1c_run_does(tmp_path: Path) -> None:
    (tmp_path / "p.ilc").write_bytes(compiled(CASE.source, 0))
    (tmp_path / "p.sensors.json").write_text(json.dumps(CASE.script), encoding="utf-8")
    alone = json.loads(rl1c("run", tmp_path / "p.ilc", "--sensors", tmp_path / "p.sensors.json",
                            "--format", "json").stdout)
    jobs = "\n".join([_job(CASE.source, CASE.script), _job("A=5\n", {}, 3)]) + "\n"
    result = rl1c("run", "--batch", stdin=jobs.encode())
    assert result.exit_code == 0, result.output
    first, second = map(json.loads, result.stdout.splitlines())
    assert first["status"] == alone["status"] and first["variables"] == alone["variables"]
    assert first["trace"] == [{key: entry[key] for key in ("time", "call", "args", "result")
                               if key in entry} for entry in alone["trace"]]
    assert second["variables"]["A"] == 5


@pytest.mark.parametrize(("job", "said"), [
    ("not json", "the job is no JSON line"),
    ('{"ilc": "AA==", "sensors": {}}', "expected {\"ilc\": BASE64"),
    ('{"ilc": "AA==", "sensors": {}, "budget": 0}', "with N from 1 to"),
    ('{"ilc": "AA==", "sensors": {}, "budget": true}', "with N from 1 to"),
    ('{"ilc": "!!", "sensors": {}, "budget": 5}', "the job's ilc is not base64"),
    ('{"ilc": "AA==", "sensors": {"XYZ": 1}, "budget": 5}', "the job's sensors"),
    ('{"ilc": "AA==", "sensors": {"\\ud800": 1}, "budget": 5}', "half of a UTF-16 pair"),
    ('{"ilc": "AAAA", "sensors": {}, "budget": 5}', "not valid intermediate code"),
])
def test_rl1c_run_batch_answers_a_job_it_cannot_run_and_goes_on(job: str, said: str) -> None:
    result = rl1c("run", "--batch", stdin=f"{job}\n{_job('A=5', {})}\n".encode())
    assert result.exit_code == 0, result.output
    refused, ran = map(json.loads, result.stdout.splitlines())
    assert refused["status"]["code"] in ("bad-job", "invalid-ilc")
    assert said in refused["status"]["message"]
    assert ran["variables"]["A"] == 5


def test_rl1c_run_batch_takes_no_file() -> None:
    result = rl1c("run", "x.ilc", "--batch")
    assert result.exit_code == 2 and "give it without FILE" in result.stderr


def test_the_reference_as_a_batch_engine_agrees_at_each_level() -> None:
    for level in ("", "-O2"):
        result = rl1c("fuzz", "--engine", "vm-O0", "--engine",
                      REFERENCE.replace("exec-batch:", f"exec-batch{level}:"),
                      "--count", "25", "--seed", "2", "--jobs", "2")
        assert result.exit_code == 0, result.output
        assert "seed 2: all agreed" in result.stdout


def test_one_engine_process_answers_every_job() -> None:
    engine = engine_named(REFERENCE)
    assert isinstance(engine, BatchEngine)
    started = differential._BATCHES.get(engine.command)
    for number in range(3):
        case = Run(f"A={number}\n", {})
        assert engine.run(case, 100).document["variables"]["A"] == number
        process = differential._BATCHES[engine.command].process
        assert process is not None and (started is None or number == 0
                                         or process is started.process)
        started = differential._BATCHES[engine.command]


@pytest.fixture
def quick_timeout(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(differential, "EXEC_TIMEOUT", 1.0)


@pytest.mark.usefixtures("quick_timeout")
@pytest.mark.parametrize(("command", "code", "said"), [
    ("exit 3", "no-run", "(exit status 3)"),  # before reading the job, or answering
    ("echo oops >&2; exit 1", "no-run", "its standard error ends: oops"),
    ("cat > /dev/null", "timeout", "it answered no job in 1 seconds"),
    # Alive, it was said to have ended.
    ("read job; exec >&-; sleep 30", "no-run", "it closed its standard output before "
                                               "answering"),
    ("yes", "no-run", "it printed more than one line for one job"),
    ("read job; echo '{\"status\": 1}'; cat > /dev/null", "no-run",
     "its object has no variables nor trace"),
    ("read job; echo '{\"status\":\"ok\",\"variables\":{},\"trace\":[]}'; exit 0", "ok", ""),
])
def test_a_dead_lying_or_hanging_engine_is_a_run_that_disagrees_never_a_hang(
        command: str, code: str, said: str) -> None:
    engine = _batch(command)
    started = time.monotonic()
    observation = engine.run(CASE, 20_000)
    assert time.monotonic() - started < 60  # a hang guard: the timeout is 1 s
    status = observation.document["status"]
    assert observation.ending()["code"] == code  # type: ignore[index]
    if said:
        assert said in status["message"]
    verdict = judge(CASE, [VmEngine(0), engine], 20_000)
    assert verdict.problems  # never agrees: it ran nothing of the program


@pytest.mark.usefixtures("quick_timeout")
def test_an_engine_that_closes_its_input_alive_says_so() -> None:
    """It was said to have ended. The job (its sensor script) is longer than a pipe
    holds, so that the engine closes its input while the job is being written."""
    engine = _batch("head -c 100 > /dev/null; exec 0<&-; sleep 30")
    case = Run(CASE.source, {"ULT A": list(range(30_000))})
    status = engine.run(case, 20_000).document["status"]
    assert status["message"] == "it closed its standard input before reading the job"


def test_an_engine_that_dies_is_started_again_at_the_next_job() -> None:
    # Answers one job with the reference's run, then ends. The usual timeout: no job
    # waits for it, and a start of rl1c on a loaded machine can take more than 1 s.
    once = (f"read job; echo \"$job\" | {RL1C} run --batch")
    engine = _batch(once)
    answers = [engine.run(Run(f"A={number}\n", {}), 100) for number in range(3)]
    assert [answer.ending()["code"] for answer in answers] == ["ok", "no-run", "ok"]  # type: ignore[index]
    assert answers[2].document["variables"]["A"] == 2


def test_a_second_answer_that_comes_late_is_no_answer_to_the_next_job(tmp_path: Path
                                                                      ) -> None:
    """Found by the hostile pass: an engine that answered a job twice, the second line
    after a while, had that line taken for its answer to the next job (A=99 for a
    program setting A=1), unseen."""
    run = '{"status":"ok","variables":{"A":%s},"trace":[]}'
    written = tmp_path / "written"
    engine = _batch(f"while read job; do echo '{run % 0}'; sleep 0.2; echo '{run % 99}'; "
                    f"touch {shlex.quote(str(written))}; done")
    assert engine.run(Run("A=0\n", {}), 100).ending()["code"] == "ok"  # type: ignore[index]
    deadline = time.monotonic() + 60
    while not written.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    late = engine.run(Run("A=1\n", {}), 100).document
    assert late["status"] == {"code": "no-run", "line": None, "message": (
        "it printed a line after its answer to the job before (two lines for one job)")}


def test_an_engine_past_its_output_cap_is_stopped(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(differential, "EXEC_OUTPUT_LIMIT", 2**20)
    observation = _batch("head -c 3000000 /dev/zero; sleep 30").run(CASE, 20_000)
    assert observation.ending()["code"] == "too-much-output"  # type: ignore[index]


@pytest.mark.usefixtures("quick_timeout")
def test_a_stopped_engine_leaves_no_process_behind(tmp_path: Path) -> None:
    pid_file = tmp_path / "pid"
    engine = _batch(f"sleep 300 & echo $! > {pid_file}; cat > /dev/null")
    assert engine.run(CASE, 20_000).ending()["code"] == "timeout"  # type: ignore[index]
    pid = int(pid_file.read_text(encoding="ascii"))
    if not ends_within(pid, seconds=10.0):
        os.kill(pid, 9)
        pytest.fail("the engine's child still runs")


def test_a_reproducer_of_a_batch_engine_names_its_job(tmp_path: Path) -> None:
    engine = _batch("exit 3")
    finding = fuzz.Finding(CASE, judge(CASE, [VmEngine(0), engine], 20_000))
    folder = Path(fuzz.write_reproducer(str(tmp_path), finding, [VmEngine(0), engine],
                                        20_000).folder)
    job = json.loads((folder / "job-O0.json").read_text(encoding="utf-8"))
    assert base64.b64decode(job["ilc"]) == compiled(CASE.source, 0)
    assert job["sensors"] == CASE.script and job["budget"] == 20_000
    assert "#   exit 3 < job-O0.json" in (folder / "replay.sh").read_text(encoding="utf-8")
    assert ROOT.exists()


_JSON = st.recursive(st.none() | st.booleans() | st.integers() | st.text(max_size=5),
                     lambda inner: st.lists(inner, max_size=3)
                     | st.dictionaries(st.text(max_size=5), inner, max_size=3), max_leaves=8)


@given(st.one_of(
    st.binary(max_size=300).map(lambda data: data.replace(b"\n", b"")),
    st.fixed_dictionaries({"ilc": st.one_of(_JSON, st.binary(max_size=60).map(
        lambda data: base64.b64encode(data).decode())), "sensors": _JSON,
        "budget": _JSON}).map(lambda job: json.dumps(job).encode()),
))
def test_rl1c_run_batch_answers_any_line_with_one_run_line(line: bytes) -> None:
    answers = io.StringIO()
    assert run_batch.serve(io.BytesIO(line + b"\n"), answers, "vm", DEFAULT_TIME_LIMIT_MS) == 0
    answer, = answers.getvalue().splitlines()
    document = json.loads(answer)
    assert differential._shape_problem(document) is None  # a run, as the fuzzer reads it
