"""`rl1c fuzz` campaigns: searches spread over processes (--jobs), stopped by signals,
going on past findings (--keep-going), seeded from a corpus, and their statistics."""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from pathlib import Path
from typing import Any, TypeVar

import pytest
from support import ROOT
from support.cli import rl1c
from support.planted import BROKEN_VM
from support.recording import Recording

from rl1.compiler import fuzz
from rl1.compiler.cli import fuzz as fuzz_cli
from rl1.compiler.differential import Engine, Observation, Verdict, VmEngine, judge, signature
from rl1.compiler.strategies import Run
from rl1.vm import isa

pytestmark = pytest.mark.slow  # campaigns, on pools of processes

T = TypeVar("T")

RL1C = [str(Path(sys.executable).with_name("rl1c"))]


class _TwoBugs:
    """The -O0 VM with two bugs, each common in generated programs: a crash on any
    program with an `^` (a compiler's bug), and A off by one at the end of one with a
    `+`."""

    name = "two-bugs"
    level = 0

    def run(self, case: Run, budget: int) -> Observation:
        if "^" in case.source:
            raise ValueError(f"no register left for {case.source.count('^')} operators")
        observation = VmEngine(0).run(case, budget)
        if "+" not in case.source:
            return observation
        variables = observation.document["variables"]
        return Observation({**observation.document,
                            "variables": {**variables, "A": variables["A"] + 1}})


def _campaign(engines: list[Engine], jobs: int, count: int, **options: object
              ) -> fuzz.Outcome:
    def quiet(programs: int, elapsed: float, shrinking: int) -> None:
        pass

    if jobs == 1:
        return fuzz.campaign(engines, 20_000, count=count, seconds=None, seed=11,
                             progress=quiet, **options)  # type: ignore[arg-type]
    with ProcessPoolExecutor(jobs) as pool:
        return fuzz.campaign(engines, 20_000, count=count, seconds=None, seed=11,
                             progress=quiet, executor=pool, jobs=jobs,
                             **options)  # type: ignore[arg-type]


def test_a_seed_gives_the_same_programs_on_any_number_of_processes(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fuzz, "BATCH", 4)  # 12 programs in three searches
    seen = []
    for jobs in (1, 2, 3):
        path = tmp_path / f"jobs-{jobs}"
        outcome = _campaign([VmEngine(0), Recording(path)], jobs, 12)
        assert outcome.programs == 12 and outcome.finding is None
        seen.append(sorted(path.read_text(encoding="utf-8").splitlines()))
    assert seen[0] == seen[1] == seen[2] and len(seen[0]) == 12


def test_the_finding_is_the_first_in_search_order_whatever_the_processes(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 30)
    monkeypatch.setattr(fuzz, "BATCH", 5)
    engines: list[Engine] = [VmEngine(0), _TwoBugs()]
    one, two = (_campaign(engines, jobs, 100) for jobs in (1, 2))
    assert one.finding is not None and two.finding is not None
    assert one.finding.case == two.finding.case
    # Every search that ran counts, the ones after the finding's too.
    assert two.programs >= one.programs


def test_the_summary_counts_every_process_programs() -> None:
    result = rl1c("fuzz", "--count", "30", "--seed", "5", "--jobs", "2")
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("fuzz: 30 programs in ")
    assert "; seed 5: all agreed" in result.stdout


STARTED_WITHIN = 120  # s for a campaign to run its first programs on a loaded machine


def _programs_told(temporary: Path) -> bool:
    """Whether a search of the campaign whose temporary folder is `temporary` has told
    that it has run programs (in its fuzz.Channel: the count that starts `told-INDEX`)."""
    for told in temporary.glob("rl1-fuzz-*/told-*"):
        with contextlib.suppress(OSError, ValueError):  # gone, or not written whole
            if told.suffix == "" and int(told.read_text().split(" ")[0]) > 0:
                return True
    return False


def _stopped(tmp_path: Path, signum: int, *args: str,
             ready: Callable[[Path], bool] = _programs_told) -> tuple[int, str]:
    """`rl1c fuzz ARGS` given `signum` once `ready(its temporary folder)` (by default,
    once it has run programs): its status and output."""
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    process = subprocess.Popen([*RL1C, "fuzz", "--time", "300", "--out", str(tmp_path),
                                *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, cwd=tmp_path,
                               env={**os.environ, "TMPDIR": str(temporary)})
    try:
        deadline = time.monotonic() + STARTED_WITHIN
        while not ready(temporary):
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, f"not ready in {STARTED_WITHIN} s"
            time.sleep(0.1)
        process.send_signal(signum)
        out, err = process.communicate(timeout=60)
    finally:
        process.kill()
    return process.returncode, out + err


@pytest.mark.parametrize(("signum", "jobs"), [(signal.SIGINT, "1"), (signal.SIGTERM, "2")])
def test_a_signal_stops_the_campaign_with_its_summary_and_seed(
        tmp_path: Path, signum: int, jobs: str) -> None:
    status, output = _stopped(tmp_path, signum, "--jobs", jobs)
    assert status == 128 + signum, output
    summary = re.search(r"fuzz: ([0-9]+) programs in .*; seed ([0-9]+), stopped by a "
                        r"signal before its end: all agreed so far", output)
    assert summary is not None, output
    assert int(summary.group(1)) > 0
    assert "Traceback" not in output
    assert not [name for name in os.listdir(tmp_path) if name.startswith("finding-")]


# --keep-going ---------------------------------------------------------------------------


def test_keep_going_groups_findings_by_signature_each_with_a_reproducer_that_shows_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 20)
    monkeypatch.setattr(fuzz, "BATCH", 60)
    engines: list[Engine] = [VmEngine(0), _TwoBugs()]
    written: dict[str, str] = {}

    def write(finding: fuzz.Finding) -> None:
        assert finding.signature not in written  # each signature is written once
        written[finding.signature] = fuzz.write_reproducer(str(tmp_path), finding, engines,
                                                           20_000).folder

    outcome = _campaign(engines, 2, 120, keep_going=True, found=write)
    assert outcome.programs == 120  # it went on past every finding
    assert "two-bugs: crashed: ValueError: no register left for N operators" in written
    assert len(written) >= 2 and set(written) == set(outcome.counts) == set(outcome.findings)
    assert sum(outcome.counts.values()) <= outcome.programs
    for name, folder in written.items():
        # Shrunk keeping its signature: the reproducer shows the kind it is filed under.
        case = Run((Path(folder) / fuzz.SOURCE).read_text(encoding="utf-8"),
                   json.loads((Path(folder) / fuzz.SCRIPT).read_text(encoding="utf-8")))
        assert judge(case, engines, 20_000).problems
        assert signature(judge(case, engines, 20_000)) == name


class _LastFirst(Executor):
    """Runs each search at once in this process, but makes it known only when the next
    one is submitted (or a second after the last): of the searches under way, the latest
    always ends first, as a slow first search on a pool makes it."""

    def __init__(self) -> None:
        self._held: list[tuple[Future[Any], Any]] = []
        self._timer: threading.Timer | None = None

    def submit(self, fn: Callable[..., T], /, *args: Any, **kwargs: Any) -> Future[T]:
        if self._timer is not None:
            self._timer.cancel()
        future: Future[T] = Future()
        future.set_running_or_notify_cancel()
        result = fn(*args, **kwargs)
        if self._held:  # this one ends now, the one held later
            future.set_result(result)
        else:
            self._held.append((future, result))
        self._timer = threading.Timer(1.0, self._release)
        self._timer.start()
        return future

    def _release(self) -> None:
        if self._held:
            future, result = self._held.pop()
            future.set_result(result)


def test_keep_going_finds_the_same_reproducers_whatever_order_the_searches_end_in(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # A signature's finding was the first search's to end: the first search's own,
    # found too by later ones, was dropped when they ended before it.
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 10)
    monkeypatch.setattr(fuzz, "BATCH", 10)
    engines: list[Engine] = [VmEngine(0), _TwoBugs()]

    def quiet(programs: int, elapsed: float, shrinking: int) -> None:
        pass

    told: dict[str, list[fuzz.Finding]] = {"in order": [], "last first": []}
    outcomes = {order: fuzz.campaign(
        engines, 20_000, count=60, seconds=None, seed=11, progress=quiet,
        executor=executor, jobs=2, keep_going=True, found=told[order].append)
        for order, executor in (("in order", None), ("last first", _LastFirst()))}
    assert told["in order"] and told["last first"] == told["in order"]
    assert outcomes["last first"].findings == outcomes["in order"].findings
    assert outcomes["last first"].counts == outcomes["in order"].counts


@pytest.mark.parametrize(("problems", "same"), [
    (["x: trace entry 3: MOV 1,2 at 40 ms / MOV 1,3 at 40 ms",
      "x: trace entry 1: MOV -5,7 at 0 ms / MOV 2,2 at 0 ms"], True),
    (["x: trace entry 3: MOV 1,2 at 40 ms / LINE LOST 0 at 40 ms",
      "x: trace entry 3: MOV 1,2 at 40 ms / MOV 1,3 at 40 ms"], False),
    (["x: ending: fault budget at line 3 / ended normally",
      "x: ending: fault budget at line 12 / ended normally"], True),
    (["x: variables: A 1 / 2", "x: variables: B 7 / -7, C 0 / 1"], True),
    (["x: variables: A 1 / 2", "y: variables: A 1 / 2"], False),
    (["vm-O1: ran 9 instructions, -O0 8", "vm-O1: ran 12 instructions, -O0 3"], True),
])
def test_a_signature_leaves_out_what_varies_between_programs_of_one_bug(
        problems: list[str], same: bool) -> None:
    verdicts = [Verdict({"x": Observation({}), "y": Observation({}),
                              "vm-O1": Observation({})}, [problem]) for problem in problems]
    assert (signature(verdicts[0]) == signature(verdicts[1])) is same


def test_keep_going_lists_each_signature_with_its_count_and_folder(tmp_path: Path) -> None:
    result = rl1c("fuzz", "--engine", "ast", "--engine", "exec:echo not json",
                  "--count", "3", "--seed", "4", "--keep-going", "--out", tmp_path)
    assert result.exit_code == 1, result.output
    # Every program disagrees (the engine prints no run): a trace cut short, or, for a
    # program without calls, an ending; each kind with its count and its folder.
    groups = re.findall(r"\n +([0-9]+)  exec:echo not json: [^\n]+\n +reproducer: "
                        r"([^;]+); replay: sh (\S+)", result.stdout)
    kinds = len(groups)
    assert f"seed 4: {kinds} kind{'s' if kinds > 1 else ''} of disagreement (reference: " \
        "ast), by the programs that showed each:" in result.stdout
    assert sum(int(count) for count, _, _ in groups) == 3
    assert sorted(folder for _, folder, _ in groups) == sorted(
        str(tmp_path / name) for name in os.listdir(tmp_path))
    assert all(replay == f"{folder}/replay.sh" for _, folder, replay in groups)


def test_a_signal_keeps_the_reproducers_of_a_campaign_that_goes_on(tmp_path: Path) -> None:
    status, output = _stopped(tmp_path, signal.SIGTERM, "--jobs", "2", "--keep-going",
                              "--engine", "ast", "--engine", "exec:echo not json",
                              ready=lambda _: any(tmp_path.glob("finding-*/replay.sh")))
    assert status == 143, output
    assert re.search(r"fuzz: [0-9]+ programs in .*; seed [0-9]+, stopped by a signal "
                     r"before its end: [0-9]+ kinds? of disagreement", output), output
    folders = re.findall(r"reproducer: ([^;]+);", output)
    assert folders and all((Path(folder) / "replay.sh").is_file() for folder in folders)


# --corpus -------------------------------------------------------------------------------



def test_a_corpus_runs_first_and_its_disagreement_is_shrunk_and_written(
        tmp_path: Path) -> None:
    corpus, out = tmp_path / "corpus", tmp_path / "out"
    corpus.mkdir()
    (corpus / "shift.rob").write_text("' a wrong shift, with lines around it\n"
                                      "B=2\nA=1<-1\nC=3\n", encoding="utf-8")
    result = rl1c("fuzz", "--engine", "vm-O0", "--engine", BROKEN_VM, "--corpus", corpus,
                  "--count", "1", "--seed", "1", "--jobs", "1", "--out", out)
    assert result.exit_code == 1, result.output
    assert "programs (the corpus of 1 first)" in result.stdout
    # Its first program, whatever the generated one does; every line it does not need
    # deleted.
    assert (out / "finding-1" / "program.rob").read_text(encoding="utf-8") == "A=1<-1\n"


def test_a_corpus_takes_each_program_with_the_script_beside_it(tmp_path: Path) -> None:
    (tmp_path / "past" / "finding-1").mkdir(parents=True)
    (tmp_path / "past" / "finding-1" / "program.rob").write_text("A=(ULT A)\n")
    (tmp_path / "past" / "finding-1" / "program.sensors.json").write_text(
        '{"ULT A": [12]}')
    (tmp_path / "toml.rob").write_text("A=1\n")
    (tmp_path / "toml.sensors.toml").write_text('comment = "none read"\n')
    (tmp_path / "bare.rob").write_text("B=2\n")
    (tmp_path / "wrong.rob").write_text("#10\n")  # a jump to no label
    (tmp_path / "badscript.rob").write_text("C=3\n")
    (tmp_path / "badscript.sensors.json").write_text('{"XYZ": 1}')
    runs, warnings = fuzz.read_corpus([str(tmp_path / "past"), str(tmp_path / "toml.rob"),
                                       str(tmp_path)])
    assert runs[:2] == [Run("A=(ULT A)\n", {"ULT A": [12]}),
                        Run("A=1\n", {"comment": "none read"})]
    assert [run.source for run in runs[2:]] == ["B=2\n", "A=(ULT A)\n", "A=1\n"]
    assert runs[2].script == {}
    assert len(warnings) == 2
    assert all(warning.endswith("; left out of the corpus") for warning in warnings)
    assert any(str(tmp_path / "wrong.rob") in warning and "checker finds errors" in warning
               for warning in warnings)
    assert any(str(tmp_path / "badscript.sensors.json") in warning for warning in warnings)


def test_a_corpus_path_that_is_not_there_is_a_usage_error(tmp_path: Path) -> None:
    result = rl1c("fuzz", "--corpus", tmp_path / "nothing")
    assert result.exit_code == 2
    assert f"argument --corpus: {tmp_path / 'nothing'}: no such file or folder" \
        in result.stderr


# Progress -------------------------------------------------------------------------------


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_is_a_plain_line_every_few_seconds_off_a_terminal() -> None:
    stream = io.StringIO()
    bar = fuzz_cli._Bar(1000, None, stream)
    every = fuzz_cli.PROGRESS_EVERY
    for programs, elapsed in [(1, 0.5), (10, every - 0.1), (40, every), (41, every + 1),
                              (90, 2 * every + 3)]:
        bar.update(programs, elapsed)
    bar.close()
    assert stream.getvalue() == (
        f"fuzz: 40 of 1000 programs, {40 / every:.1f} per second, {every:.0f} s\n"
        f"fuzz: 90 of 1000 programs, {90 / (2 * every + 3):.1f} per second, "
        f"{2 * every + 3:.0f} s\n")


def test_progress_on_a_terminal_is_a_bar_redrawn_in_place() -> None:
    stream = _Terminal()
    bar = fuzz_cli._Bar(None, 60, stream)
    bar.update(10, 1.0)
    bar.update(11, 1.1)  # too soon to redraw
    bar.update(20, 30.0)
    bar.close()
    assert stream.getvalue() == (
        f"\r[{'.' * 30}] 10 programs, 10.0 per second, 1 of 60 s\033[K"
        f"\r[{'#' * 15}{'.' * 15}] 20 programs, 0.7 per second, 30 of 60 s\033[K\n")


def test_progress_says_the_findings_being_shrunk_after_the_last_program() -> None:
    # "20 of 20 programs" while two searches went on shrinking their findings, for as
    # long again, looked like a campaign that hung.
    stream = io.StringIO()
    bar = fuzz_cli._Bar(20, None, stream)
    every = fuzz_cli.PROGRESS_EVERY
    bar.update(20, every, 2)
    bar.update(20, 2 * every, 1)
    bar.close()
    assert stream.getvalue() == (
        f"fuzz: 20 of 20 programs, {20 / every:.1f} per second, {every:.0f} s; shrinking "
        "2 findings\n"
        f"fuzz: 20 of 20 programs, {10 / every:.1f} per second, {2 * every:.0f} s; "
        "shrinking 1 finding\n")
    terminal = _Terminal()
    bar = fuzz_cli._Bar(20, None, terminal)
    bar.update(20, 1.0, 1)
    bar.update(20, 2.0)
    assert terminal.getvalue() == (
        f"\r[{'#' * 30}] 20 of 20 programs, 20.0 per second, 1 s; shrinking 1 finding\033[K"
        f"\r[{'#' * 30}] 20 of 20 programs, 10.0 per second, 2 s\033[K")


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_campaign_tells_the_findings_it_shrinks(monkeypatch: pytest.MonkeyPatch,
                                                  jobs: int) -> None:
    monkeypatch.setattr(fuzz, "SHRINK_ATTEMPTS", 30)
    monkeypatch.setattr(fuzz, "POLL", 0.01)  # a look at the searches between any two
    monkeypatch.setattr(fuzz, "TOLD_EVERY", 3600.0)  # told only as they start shrinking
    told: list[tuple[int, int]] = []

    def progress(programs: int, elapsed: float, shrinking: int) -> None:
        told.append((programs, shrinking))

    with ProcessPoolExecutor(jobs) if jobs > 1 else contextlib.nullcontext() as pool:
        outcome = fuzz.campaign([VmEngine(0), _TwoBugs()], 20_000, count=100, seconds=None,
                                seed=11, progress=progress, executor=pool, jobs=jobs)
    assert outcome.finding is not None
    assert any(shrinking == 1 for _, shrinking in told), told


def test_a_campaign_in_ci_prints_progress_lines_on_standard_error(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fuzz_cli, "PROGRESS_EVERY", 0.0)
    result = rl1c("fuzz", "--count", "12", "--seed", "5", "--jobs", "2")
    assert result.exit_code == 0, result.output
    lines = result.stderr.splitlines()
    assert lines and all(re.fullmatch(r"fuzz: [0-9]+ of 12 programs, [0-9.]+ per second, "
                                      r"[0-9]+ s", line) for line in lines), lines
    assert "\r" not in result.stderr


# --format json --------------------------------------------------------------------------


def _documented_keys() -> list[str]:
    """The keys of `--format json` as spec/optimization.md's table lists them."""
    spec = (ROOT / "spec" / "optimization.md").read_text(encoding="utf-8")
    table = spec.split("`--format json` prints", 1)[1].split("\n\n", 2)[1]
    return re.findall(r"^\| `([a-z_]+)` \|", table, re.MULTILINE)


def _statistics(*args: str) -> dict[str, object]:
    result = rl1c("fuzz", "--format", "json", "--seed", "3", *args)
    assert result.exit_code in (0, 1), result.output
    assert result.stderr.startswith("fuzz: ")  # the summary for people, apart
    document = json.loads(result.stdout)
    assert isinstance(document, dict)
    return document


def test_json_statistics_have_the_keys_the_spec_lists_and_add_up() -> None:
    document = _statistics("--count", "30", "--jobs", "2")
    assert list(document) == _documented_keys()
    assert document["programs"] == 30 and document["corpus"] == 0 and not document["stopped"]
    assert document["engines"] == ["ast", "vm-O0", "vm-O1", "vm-O2"]
    endings = document["endings"]
    assert isinstance(endings, dict) and sum(endings.values()) == 30
    opcodes, fused = document["opcodes"], document["superinstructions"]
    assert isinstance(opcodes, dict) and isinstance(fused, dict)
    assert list(opcodes) == list(fused) == ["vm-O0", "vm-O1", "vm-O2"]
    # Each program ends once, on (END) or a fault: -O0 ran one END per normal ending.
    assert opcodes["vm-O0"].get("END", 0) == endings.get("ok", 0)
    assert fused["vm-O0"] == fused["vm-O1"] == {} and fused["vm-O2"]
    assert all(opcodes["vm-O2"][name] == count for name, count in fused["vm-O2"].items())
    # -O2's own opcodes: 1.2's superinstructions and 1.3's compact calls alike.
    assert {isa.BY_NAME[name].minor for name in fused["vm-O2"]} == {isa.FUSED_MINOR,
                                                                    isa.COMPACT_MINOR}
    passes = document["passes"]
    assert isinstance(passes, dict) and "fuse" in passes
    assert all(0 < count <= 30 for count in passes.values())
    assert document["findings"] == []


def test_json_statistics_are_the_same_for_any_number_of_processes() -> None:
    one, two = (_statistics("--count", "24", "--jobs", jobs) for jobs in ("1", "2"))
    assert {**one, "seconds": 0} == {**two, "seconds": 0}


def test_json_statistics_list_each_finding_with_its_folder(tmp_path: Path) -> None:
    document = _statistics("--engine", "ast", "--engine", "exec:echo not json", "--count",
                           "3", "--keep-going", "--out", str(tmp_path), "--jobs", "1")
    findings = document["findings"]
    assert isinstance(findings, list) and findings
    assert sum(finding["programs"] for finding in findings) == 3
    assert sorted(finding["reproducer"] for finding in findings) == sorted(
        str(tmp_path / name) for name in os.listdir(tmp_path))


def test_statistics_count_a_lost_line_that_jumps_to_its_handler() -> None:
    # Tracing mode 3 loses the line during MOV 250 ms in: Table 4 sends it to :96.
    lost = Run("(TRC 3); (MOV 10,10); (TIM 50); (END)\n:96 (HLD); (END)\n",
               {"line_lost": [{"during": "MOV", "nth": 1, "after": 250}]})
    kept = Run(lost.source, {})
    statistics = fuzz.Statistics()
    for case in (lost, kept):
        statistics.add(case, judge(case, [VmEngine(0, counting=True)], 20_000))
    assert statistics.handler_jumps == 1
    assert statistics.endings == {"ok": 2}
    assert statistics.opcodes["vm-O0"]["HLD"] == 1  # the handler's, run once


class _Lost(Exception):
    """A search lost with its worker, as Dask's KilledWorker says."""


class _LosingOnce(Executor):
    """Runs each search in this process, but loses the first submission of search 0."""

    def __init__(self) -> None:
        self.submitted: list[int] = []

    def submit(self, fn: Callable[..., T], /, *args: Any, **kwargs: Any) -> Future[T]:
        future: Future[T] = Future()
        task = args[0]
        self.submitted.append(task.index)
        if self.submitted.count(task.index) == 1 and task.index == 0:
            future.set_exception(_Lost("the worker was killed"))
        else:
            future.set_result(fn(*args, **kwargs))
        return future


def test_a_search_lost_with_its_worker_runs_again_and_the_count_is_exact(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fuzz, "BATCH", 4)
    executor = _LosingOnce()

    def on(executor: Executor, lost: tuple[type[BaseException], ...]) -> fuzz.Outcome:
        return fuzz.campaign([VmEngine(0), VmEngine(1)], 20_000, count=12, seconds=None,
                             seed=11, progress=lambda *_: None,
                             executor=executor, jobs=2, lost=lost)

    assert on(executor, (_Lost,)).programs == 12
    assert sorted(executor.submitted) == [0, 0, 1, 2]
    with pytest.raises(_Lost):  # an error that is no loss is not hidden
        on(_LosingOnce(), ())
