"""What `rl1c test` prints (compiler/program_tests.py runs the tests): a character per
test as it finishes (. passed, F failed, E an error), then each failure and error with
the run's story (the last entries of its trace, then how it ended as `rl1c sim` or
`rl1c run` reports it: the fault on its source line, the goal's verdict, the variables)
and the command that replays it, and a summary line; and the JUnit XML of `--junit`."""

from __future__ import annotations

import re
import shlex
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, replace

from rl1.compiler.program_tests import Case, Outcome, Status, Story
from rl1.compiler.reporting.render import FileDiagnostics, diagnostic_blocks
from rl1.compiler.test_file import CONTROL, Success
from rl1.vm.defaults import DEFAULT_BUDGET
from rl1.vm.scripted import LOST, ScriptedDevice, TraceEntry
from rl1.vm.sim.device import SimEntry

from . import run_report, sim_report
from .running import Ran
from .sim_campaign import Setting, summary

LAST_ENTRIES = 10  # of a failed run's trace, shown in its story
MARKS: dict[Status, str] = {"passed": ".", "failed": "F", "error": "E"}


@dataclass(frozen=True, slots=True)
class Result:
    """A test and how it went; one that did not pass, with its story told (`finished`):
    as printed, and without colour for the JUnit XML."""

    case: Case
    outcome: Outcome
    printed: str = ""
    plain: str = ""

    @property
    def title(self) -> str:
        """`examples/listing1.tests.toml: the test's name`, as the report heads it."""
        return f"{self.case.file}: {CONTROL.sub(chr(0xFFFD), self.case.test.name)}"


def finished(case: Case, outcome: Outcome, jobs: int, *, color: bool) -> Result:
    """The Result of a test that ran. One that did not pass keeps its story as text, and
    not the run it tells of: a report of thousands of failures cannot hold each run's
    device and trace (2,000 failed runs on a world took 500 MB)."""
    result = Result(case, outcome)
    if outcome.status == "passed":
        return result
    plain = story_text(result, jobs)
    printed = story_text(result, jobs, color=True) if color else plain
    told = replace(outcome, story=None, tally=None, task=None, diagnostics=(), source=None)
    return Result(case, told, printed, plain)


def _setting(case: Case, jobs: int) -> Setting:
    """The `rl1c sim` command line of the test's run (its campaign, for a success rate)."""
    test = case.test
    success = test.expect.success
    runs = success.runs if isinstance(success, Success) else 1
    return Setting(case.program, case.world or "", test.seed, runs, jobs, test.engine,
                   test.budget)


def replay_command(case: Case, jobs: int) -> str:
    """The command that makes the test's run again with its whole report: `rl1c sim`
    (with --runs, for a success rate), or `rl1c run`."""
    test = case.test
    if case.world is not None:
        setting = _setting(case, jobs)
        if isinstance(test.expect.success, Success):
            return setting.rest(test.seed, setting.runs)
        return setting.replay(test.seed)
    words = ["rl1c", "run", case.program]
    if case.sensors is not None:
        words += ["--sensors", case.sensors]
    if test.engine != "vm":
        words += ["--engine", test.engine]
    if test.budget != DEFAULT_BUDGET:
        words += ["--budget", str(test.budget)]
    return shlex.join(words)


def story_text(result: Result, jobs: int, *, color: bool = False) -> str:
    """A failure's or an error's section of the report."""
    case, outcome = result.case, result.outcome
    lines = [f"{'_' * 8} {result.title} {'_' * 8}", *outcome.problems]
    if outcome.diagnostics:
        lines.append(diagnostic_blocks(FileDiagnostics(case.program, outcome.source,
                                                       list(outcome.diagnostics)),
                                       color=color).rstrip("\n"))
    if outcome.story is not None:
        lines += _run_lines(outcome.story, case, color)
    if outcome.tally is not None and outcome.task is not None:
        lines.append(summary(_setting(case, jobs), outcome.tally, outcome.task,
                             stopped=False).rstrip("\n"))
    if outcome.status == "failed":
        lines.append(f"replay: {replay_command(case, jobs)}")
    return "\n".join(lines) + "\n"


def _run_lines(story: Story, case: Case, color: bool) -> list[str]:
    """The run's last calls, then its ending as `rl1c sim` or `rl1c run` reports it."""
    trace = story.trace
    shown = trace[-LAST_ENTRIES:]
    lines = []
    if shown:
        earlier = len(trace) - len(shown)
        lines += [f"the run's last {len(shown)} calls" + (
            f" ({earlier:,} before them not shown)" if earlier else "") + ":",
                  run_report.TRACE_HEADING, *map(_entry_line, shown)]
    device, ending = story.device, story.ending
    if isinstance(device, ScriptedDevice):
        result = story.result
        report = run_report.RunReport(
            case.program, story.source_name, story.source, result, run_report.ShownTrace(()),
            story.finished.instructions, device.time,
            device.motion if result.fault is None else None, device.losses_not_met())
        text = run_report.render_text(report, color=color)
    else:
        assert ending is not None  # a simulated run has one
        text = sim_report.render_text(Ran(story.finished, story.source_name, story.source),
                                      device, case.program, ending.ended_at, ending.run_on,
                                      "none", color=color, verdict=ending.verdict)
    return [*lines, text.rstrip("\n")]


def _entry_line(entry: TraceEntry | SimEntry) -> str:
    if isinstance(entry, SimEntry):
        return run_report.entry_start(round(entry.time * 1000), entry.line) + \
            run_report.call_text(entry.call, entry.args, entry.result)
    shown = entry.describe() if entry.call == LOST else run_report.call_text(
        entry.call, entry.args, entry.result)
    return run_report.entry_start(entry.time, entry.line) + shown


def summary_line(results: Sequence[Result], seconds: float) -> str:
    """`3 passed, 1 failed, 1 error in 2.31 s`."""
    counts = _counts(results)
    words = [f"{counts['passed']} passed"]
    if counts["failed"]:
        words.append(f"{counts['failed']} failed")
    if counts["error"]:
        words.append(f"{counts['error']} error{'s' if counts['error'] != 1 else ''}")
    return f"{', '.join(words)} in {seconds:.2f} s"


def _counts(results: Sequence[Result]) -> dict[Status, int]:
    counts: dict[Status, int] = {"passed": 0, "failed": 0, "error": 0}
    for result in results:
        counts[result.outcome.status] += 1
    return counts


# JUnit XML ----------------------------------------------------------------------------

# What XML 1.0 cannot hold, even escaped (control characters, lone surrogates): a test's
# name or its story (a TOML string may hold \u0001) would make the file unreadable.
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _xml_text(text: str) -> str:
    return _NOT_XML.sub("\ufffd", text)


def junit_xml(results: Sequence[Result], seconds: float) -> bytes:
    """The results as JUnit XML, as CI services read it: <testsuites> with a
    <testsuite> per test file, a <testcase> per test (classname the file, name the
    test's), and in a test that did not pass a <failure> or an <error> whose message
    is the first problem and whose text is the story; counts and times (s) on each."""
    root = ET.Element("testsuites", _attributes("rl1c test", results, seconds))
    files: dict[str, list[Result]] = {}
    for result in results:
        files.setdefault(result.case.file, []).append(result)
    for file, found in files.items():
        suite = ET.SubElement(root, "testsuite", _attributes(
            file, found, sum(result.outcome.seconds for result in found)))
        for result in found:
            outcome = result.outcome
            case = ET.SubElement(suite, "testcase", {
                "classname": _xml_text(file), "name": _xml_text(result.case.test.name),
                "time": f"{outcome.seconds:.3f}"})
            if outcome.status != "passed":
                kind = "failure" if outcome.status == "failed" else "error"
                problem = ET.SubElement(case, kind, {
                    "message": _xml_text(outcome.problems[0] if outcome.problems else kind),
                    "type": kind})
                problem.text = _xml_text(result.plain)
    ET.indent(root)
    body: bytes = ET.tostring(root, "utf-8", xml_declaration=False)
    return b'<?xml version="1.0" encoding="utf-8"?>\n' + body + b"\n"


def _attributes(name: str, results: Sequence[Result], seconds: float) -> dict[str, str]:
    counts = _counts(results)
    return {"name": _xml_text(name), "tests": str(len(results)),
            "failures": str(counts["failed"]), "errors": str(counts["error"]),
            "skipped": "0", "time": f"{seconds:.3f}"}
