"""`rl1c run`: the reports (text and JSON), the exit status of each outcome, .rob and .ilc
inputs on both engines, a run that outlasts its script or its time, the bounded trace,
source lines in the trace, faults shown as diagnostics, and bad input of every kind
reported without a traceback."""

import json
import re
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import EXAMPLES, SAMPLE, SAMPLE_SENSORS
from support.cli import rl1c

from rl1.compiler.cli.run_report import HEAD, TAIL, select_trace
from rl1.compiler.reporting.catalogue import CODES
from rl1.compiler.runner import load_script
from rl1.vm.faults import FaultKind
from rl1.vm.language import VARIABLES
from rl1.vm.scripted import TraceEntry, decode_script

SENSORS = SAMPLE_SENSORS
SAMPLE_TOML = EXAMPLES / "sample.sensors.toml"
VECTORS = EXAMPLES.parent / "spec" / "vectors"


def report(*args: str | Path) -> tuple[int, dict[str, Any]]:
    result = rl1c("run", *args, "--format", "json")
    return result.exit_code, json.loads(result.stdout)


def program(tmp_path: Path, text: str, sensors: dict[str, Any] | None = None) -> list[str]:
    """Write p.rob (and s.json): the arguments that run them."""
    (tmp_path / "p.rob").write_text(text)
    if sensors is None:
        return [str(tmp_path / "p.rob")]
    (tmp_path / "s.json").write_text(json.dumps(sensors))
    return [str(tmp_path / "p.rob"), "--sensors", str(tmp_path / "s.json")]


def test_the_sample_runs_its_main_path_and_prints_trace_lines_and_variables() -> None:
    result = rl1c("run", SAMPLE, "--sensors", SENSORS)
    assert result.exit_code == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].split() == ["time", "ms", "line", "call"]
    assert lines[1].split() == ["0", "2", "CAM", "Z"]  # (CAM Z) is on line 2
    # A reading of several values names each.
    assert "     500     4  IMG -> area 185, x 128, y 90, angle 0\n" in result.stdout
    assert [line.split() for line in lines[-7:-3]] == [
        ["3200", "40", "MVI", "1,1,50"], ["13200", "40", "MOV", "3,3"],
        ["13200", "41", "MOV", "0,0"], ["13200", "43", "FRE"]]  # the MVI takes 10 s
    assert lines[-3] == "the program ended normally"
    assert lines[-2].startswith("variables: A=5 C=589 D=450 L=100 U=160 ")
    executed = report(SAMPLE, "--sensors", SENSORS)[1]["instructions"]
    assert lines[-1] == f"13200 ms of device time, {executed:,} instructions"
    interpreted = rl1c("run", SAMPLE, "--sensors", SENSORS, "--engine", "ast").stdout
    assert interpreted.splitlines()[-1] == ("13200 ms of device time, the interpreter "
                                            "counts no instructions")


def test_one_instruction_is_one_instruction(tmp_path: Path) -> None:
    result = rl1c("run", *program(tmp_path, "(END)\n"))
    assert result.stdout.splitlines()[-1] == "0 ms of device time, 1 instruction"


def test_a_rob_file_s_warnings_come_first_on_standard_error() -> None:
    result = rl1c("run", SAMPLE, "--sensors", SENSORS)
    assert result.stderr.startswith("warning[W0301]: a lost guidance line can jump to `:97`")
    assert "1 warning emitted" in result.stderr
    compiled = rl1c("run", SAMPLE, "--sensors", SENSORS, "--engine", "ast")
    assert compiled.stderr == result.stderr


def test_json_has_one_status_shape_the_instructions_and_engines_agree_on_lines() -> None:
    status, vm = report(SAMPLE, "--sensors", SENSORS)
    ast_status, interpreted = report(SAMPLE, "--sensors", SENSORS, "--engine", "ast")
    assert (status, ast_status) == (0, 0)
    assert vm["instructions"] > 0 and interpreted["instructions"] is None
    assert {**vm, "instructions": None} == interpreted  # the trace with its lines included
    assert vm["status"] == {"code": "ok", "exit_status": 0, "message": "the program ended",
                            "line": None}
    assert list(vm["variables"]) == list(VARIABLES)
    assert vm["variables"]["C"] == 589
    assert vm["trace"][0] == {"time": 0, "call": "CAM Z", "args": [], "line": 2}
    assert vm["trace"][6] == {"time": 300, "call": "IMG", "args": [],
                              "result": [120, 128, 90, 0], "line": 4}
    assert (vm["device_time"], vm["moving"], vm["trace_left_out"]) == (13200, None, None)


def test_the_toml_example_is_the_json_script() -> None:
    assert load_script(SAMPLE_TOML) == load_script(SENSORS)
    assert report(SAMPLE, "--sensors", SAMPLE_TOML) == report(SAMPLE, "--sensors", SENSORS)


def test_the_instructions_are_the_vm_s_count_as_the_vectors_give_it(tmp_path: Path) -> None:
    vector = next(v for v in json.loads((VECTORS / "sample.json").read_text())["vectors"]
                  if v["name"] == "listing-1")
    compiled = tmp_path / "sample.ilc"
    compiled.write_bytes(bytes.fromhex(vector["ilc_stripped"]))
    (tmp_path / "s.json").write_text(json.dumps(vector["sensors"]))
    status, document = report(compiled, "--sensors", tmp_path / "s.json")
    assert (status, document["instructions"]) == (0, vector["executed"])
    assert {entry["line"] for entry in document["trace"]} == {None}  # no line map


def test_a_compiled_ilc_runs_as_its_source(tmp_path: Path) -> None:
    compiled = tmp_path / "sample.ilc"
    assert rl1c(SAMPLE, "-o", compiled).exit_code == 0
    assert report(compiled, "--sensors", SENSORS) == report(SAMPLE, "--sensors", SENSORS)


FAULTS = [
    ("(MOV 3,3)\nS=13\n(MOV S,0)\n", None, "argument-range", 10, 3, "(MOV S,0)", "test the"),
    ("(TRC 2)\n(MOV 1,1)\n(TIM 10)\n", {"line_lost": [{"time": 300}]},
     "missing-handler", 11, 3, "(TIM 10)", "add the handler label"),
    (":10 A++\n#10\n", None, "budget", 12, 2, "#10", "if the program should run longer, "
     "raise --budget"),
    ("(MVI 3,-3,10)\n", None, "device-error", 13, 1, "(MVI 3,-3,10)", "the vehicle refused"),
]


@pytest.mark.parametrize(("source", "sensors", "code", "status", "line", "call", "help"),
                         FAULTS)
@pytest.mark.parametrize("engine", ["vm", "ast"])
def test_each_fault_kind_has_its_status_and_is_shown_as_a_diagnostic(
    tmp_path: Path, source: str, sensors: dict[str, Any] | None, code: str, status: int,
    line: int, call: str, help: str, engine: str,
) -> None:
    options = [*program(tmp_path, source, sensors), "--engine", engine, "--budget", "50"]
    exit_code, document = report(*options)
    assert exit_code == status
    assert set(document["status"]) == {"code", "exit_status", "message", "line"}
    assert (document["status"]["code"], document["status"]["exit_status"],
            document["status"]["line"]) == (code, status, line)
    assert document["trace"][-1]["call"] == "STOP"
    text = rl1c("run", *options)
    assert text.exit_code == status
    column = source.splitlines()[line - 1].index(call) + 1
    shown = text.stdout.split(f"error[E10{status}]: ")[1]  # the code of `rl1c explain`
    assert f"\n --> {tmp_path / 'p.rob'}:{line}:{column}\n" in shown
    assert f"\n{line} | {source.splitlines()[line - 1]}\n" in shown
    assert f"\n  | {' ' * (column - 1)}{'^' * len(call)}\n" in shown  # the call underlined
    assert f"= help: {help}" in shown


def test_a_fault_in_an_ilc_file_shows_its_source_when_found(tmp_path: Path) -> None:
    args = program(tmp_path, "(MOV 3,3)\nS=13\n(MOV S,0)\n")
    compiled = tmp_path / "p.ilc"
    assert rl1c(args[0], "-o", compiled).exit_code == 0
    shown = rl1c("run", compiled).stdout
    assert f" --> {tmp_path / 'p.rob'}:3:1\n" in shown and "3 | (MOV S,0)\n" in shown
    (tmp_path / "p.rob").write_text("' edited since\n")  # no longer the source compiled
    shown = rl1c("run", compiled).stdout
    assert f"S), outside -12..12 (at line 3)\n --> {compiled}\n" in shown


def test_a_run_without_a_script_stops_at_the_first_sensing_call(tmp_path: Path) -> None:
    result = rl1c("run", SAMPLE)
    assert result.exit_code == 13
    assert len(result.stdout.splitlines()) < 30
    assert "error[E1013]: (IMG) at 300 ms has no reading: no sensor script was " \
           "given\n --> " in result.stdout
    assert "= help: give the readings the program needs in a sensor script: --sensors FILE" \
           in result.stdout
    exit_code, document = report(SAMPLE)
    assert exit_code == 13
    assert [entry["call"] for entry in document["trace"][-2:]] == ["IMG", "STOP"]


def test_a_run_past_its_script_s_readings_says_which_reading_at_which_time(
        tmp_path: Path) -> None:
    args = program(tmp_path, ":10 A=(ULT B); (TIM 5)\n#10\n", {"ULT B": [7, 8, 9]})
    exit_code, document = report(*args)
    assert exit_code == 13
    assert document["status"]["message"] == (
        f"(ULT B) at 1800 ms has no reading: it is call 4, and the sensor script "
        f"{tmp_path / 's.json'} gives 3 ULT B readings")
    assert document["status"]["line"] == 1 and document["variables"]["A"] == 9
    assert "= help: add readings to the sensor script" in rl1c("run", *args).stdout


def test_after_last_repeat_runs_on_with_the_last_reading(tmp_path: Path) -> None:
    args = program(tmp_path, "A=(ULT B)\nB=(ULT B)\nC=(IMG)\n",
                   {"ULT B": [7], "after_last": "repeat"})
    exit_code, document = report(*args)
    assert exit_code == 0
    assert [document["variables"][name] for name in "ABC"] == [7, 7, 0]


def test_the_time_limit_stops_a_waiting_loop(tmp_path: Path) -> None:
    args = program(tmp_path, ":10 (TIM 1)\n#10\n")
    exit_code, document = report(*args)  # the default: an hour
    assert exit_code == 13
    assert document["status"]["message"] == ("the run reached its device-time limit of "
                                             "3600 s, during (TIM 1)")
    assert document["device_time"] == 3_600_000
    exit_code, document = report(*args, "--time-limit", "2.5")
    assert (exit_code, document["device_time"], len(document["trace"])) == (13, 2500, 27)
    assert "= help: if the program should run longer, raise --time-limit" in rl1c(
        "run", *args, "--time-limit", "1").stdout


@pytest.mark.parametrize("value", ["0", "-1", "abc", "1e99", "nan"])
def test_a_bad_time_limit_is_a_usage_error(value: str) -> None:
    result = rl1c("run", SAMPLE, "--time-limit", value)
    assert result.exit_code == 2
    assert "argument --time-limit: expected seconds from 0.001 to 2147483" in result.stderr


def test_a_long_trace_shows_its_head_and_tail_and_how_much_was_left_out(
        tmp_path: Path) -> None:
    args = program(tmp_path, "A=100\n:10 (TIM 1); A--; ?A>#10\n")
    lines = rl1c("run", *args).stdout.splitlines()
    entries = lines[1:-3]  # the heading; the ending, the variables, the time and count
    assert len(entries) == HEAD + 1 + TAIL
    assert entries[HEAD].split() == ["...", "(40", "entries", "left", "out:", "--trace",
                                     "all", "shows", "every", "one)"]
    assert entries[0].split() == ["0", "2", "TIM", "1"]
    assert entries[-1].split() == ["9900", "2", "TIM", "1"]
    every = rl1c("run", *args, "--trace", "all").stdout.splitlines()
    assert len(every) == 1 + 100 + 3
    assert rl1c("run", *args, "--trace", "none").stdout.splitlines() == lines[-3:]
    _, document = report(*args, "--trace", "short")
    assert len(document["trace"]) == HEAD + TAIL
    assert document["trace_left_out"] == {"after": HEAD, "count": 40}
    _, document = report(*args)
    assert len(document["trace"]) == 100 and document["trace_left_out"] is None


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 400))
def test_a_short_trace_of_any_length_is_bounded_and_loses_nothing_silently(
        length: int) -> None:
    log = [TraceEntry(time, "TIM", (1,)) for time in range(length)]
    shown = select_trace(log, "short")
    assert len(shown.head) + len(shown.tail) <= HEAD + TAIL + 1
    assert [*shown.head, *shown.tail] == log[:len(shown.head)] + log[length - len(shown.tail):]
    assert len(shown.head) + shown.left_out + len(shown.tail) == length
    assert shown.left_out != 1  # leaving out one entry would save no line


def test_trace_calls_leaves_out_lost_lines_and_the_stop(tmp_path: Path) -> None:
    args = program(tmp_path, "(TRC 2)\n(MOV 1,1)\n(TIM 10)\n", {"line_lost": [{"time": 300}]})
    _, every = report(*args)
    _, calls = report(*args, "--trace", "calls")
    assert [entry["call"] for entry in every["trace"]] == ["TRC", "MOV", "TIM", "LINE LOST",
                                                           "STOP"]
    assert [entry["call"] for entry in calls["trace"]] == ["TRC", "MOV", "TIM"]


def test_a_lost_line_shows_its_handler_and_a_loss_before_any_motion_is_shown(
        tmp_path: Path) -> None:
    args = program(tmp_path, "(TRC 3); (TIM 5)\n(MOV 3,3); (TIM 10)\n(END)\n:96 (MOV 0,0)\n",
                   {"line_lost": [{"time": 200}, {"time": 900}]})
    lines = rl1c("run", *args).stdout.splitlines()
    assert lines[3].split(maxsplit=2) == ["200", "1", "LINE LOST (mode 3): ignored, no "
                                                      "motion in effect"]
    assert lines[6].split(maxsplit=2) == ["900", "2", "LINE LOST (mode 3, MOV) -> :96"]
    assert lines[7].split() == ["900", "4", "MOV", "0,0"]
    _, document = report(*args)
    assert document["trace"][2] == {"time": 200, "call": "LINE LOST", "args": [3], "line": 1,
                                    "during": None, "effect": "no-motion", "handler": None}
    assert document["trace"][5]["effect"] == "jump" and document["trace"][5]["handler"] == 96


@pytest.mark.parametrize(("source", "motion"), [
    ("(MOV 3,3)\n(END)\n", "(MOV 3,3)"),
    ("(TRC 3); (MVI 3,3,100)\n(END)\n:97 (END)\n", "(MVI 3,3,100)"),
])
def test_a_program_that_ends_while_moving_says_so(tmp_path: Path, source: str,
                                                  motion: str) -> None:
    sensors = {"line_lost": [{"during": "MVI", "nth": 1, "after": 500}]}
    args = program(tmp_path, source, sensors)
    result = rl1c("run", *args)
    assert result.exit_code == 0
    assert (f"note: the program ended with {motion} in effect: the vehicle is still moving\n"
            in result.stdout)
    assert report(*args)[1]["moving"] == motion
    stopped = program(tmp_path, "(MOV 3,3)\n(MOV 0,0)\n")
    assert "note:" not in rl1c("run", *stopped).stdout


def test_bad_inputs_are_reported_naming_the_file_s_role(tmp_path: Path) -> None:
    (tmp_path / "bad.json").write_text('{"IMG": [{"area": 1}]}')
    (tmp_path / "errors.rob").write_text("A=(MOV 1,1)\n")
    compiled = tmp_path / "sample.ilc"
    rl1c(SAMPLE, "-o", compiled)
    (tmp_path / "cut.ilc").write_bytes(compiled.read_bytes()[:30])
    bad, none = tmp_path / "bad.json", tmp_path / "none.json"
    cases = [
        (("run", SAMPLE, "--sensors", bad), 2, "error[E0100]: the sensor script is not "
         f'valid: IMG[0]: missing "x", "y", "z"; write "x": ...\n --> {bad}:1\n'),
        (("run", SAMPLE, "--sensors", none), 2,
         f"error[E0100]: cannot read the sensor script `{none}`: no such file"),
        (("run", tmp_path / "errors.rob"), 1, "returns no value"),
        (("run", tmp_path / "errors.rob", "--engine", "ast"), 1, "returns no value"),
        (("run", tmp_path / "none.rob"), 2, "error[E0100]: cannot read the source file"),
        (("run", tmp_path / "cut.ilc"), 1, f"error[E0100]: the intermediate code file "
         f"`{tmp_path / 'cut.ilc'}` is not valid: byte 30: truncated"),
        (("run", tmp_path / "none.ilc"), 2, "error[E0100]: cannot read the intermediate code"),
        (("run", compiled, "--engine", "ast"), 2, "an .ilc file runs on the VM"),
        (("run", SAMPLE, "--budget", "0"), 2, "--budget"),
        (("run", SAMPLE, "--budget", str(2**31)), 2, "from 1 to 2147483647"),
        (("run", SAMPLE, "--trace", "most"), 2, "invalid choice: 'most'"),
    ]
    for args, status, message in cases:
        result = rl1c(*args)
        assert result.exit_code == status, (args, result.output)
        assert message in result.stderr, (args, result.stderr)
        assert result.stdout == "" and "Traceback" not in result.output


def test_the_help_links_the_sensor_script_page() -> None:
    help_text = rl1c("run", "--help").stdout
    assert "spec/sensors.md" in help_text
    assert re.search(r"--time-limit SECONDS\s", help_text)
    assert (EXAMPLES.parent / "spec" / "sensors.md").is_file()


def test_a_scripted_loss_that_never_happens_is_said(tmp_path: Path) -> None:
    args = program(tmp_path, "(TRC 3); (MOV 3,3); (MOV 0,0)\n(TIM 5)\n(END)\n", {"line_lost": [
        {"time": 200}, {"time": 50000}, {"during": "MOV", "nth": 1, "after": 100},
        {"during": "MVI", "nth": 1}]})
    lines = rl1c("run", *args).stdout.splitlines()
    assert lines[-5:-2] == [
        'note: the sensor script\'s line_lost[1], {"time": 50000}, never happened: the run '
        'ended before it',
        'note: the sensor script\'s line_lost[2], {"during": "MOV", "nth": 1, "after": 100}, '
        'never happened: that MOV was not in effect 100 ms after it started',
        'note: the sensor script\'s line_lost[3], {"during": "MVI", "nth": 1, "after": 1}, '
        'never happened: the run made 0 MVI calls']
    assert report(*args)[1]["losses_not_met"][0] == {
        "index": 1, "loss": {"time": 50000}, "why": "the run ended before it"}
    instruction = program(tmp_path, "A=1\nB=2\n", {"line_lost": [{"instruction": 1},
                                                                 {"instruction": 9}]})
    assert [item["index"] for item in report(*instruction)[1]["losses_not_met"]] == [1]


def test_the_spec_s_json_and_toml_examples_are_the_same_valid_script() -> None:
    page = (EXAMPLES.parent / "spec" / "sensors.md").read_text(encoding="utf-8")
    json_example = re.findall(r"```json\n(.*?)```", page, re.DOTALL)[0]
    toml_example = re.findall(r"```toml\n(.*?)```", page, re.DOTALL)[0]
    from_json = decode_script(json_example.encode(), "example.json")
    assert from_json == decode_script(toml_example.encode(), "example.toml")
    assert from_json.losses and from_json.images and from_json.ports


@pytest.mark.parametrize("kind", list(FaultKind))
def test_each_fault_kind_has_a_code_that_rl1c_explain_explains(kind: FaultKind) -> None:
    info = CODES[kind.diagnostic_code]
    assert (info.code, info.severity.value) == (f"E10{kind.exit_status}", "error")
    explained = rl1c("explain", kind.diagnostic_code.lower())
    assert explained.exit_code == 0
    assert explained.stdout.startswith(f"# {info.code}: {info.title}\n")
    assert f"`{kind.code}`" in explained.stdout  # the name JSON gives it
    assert f"exit status {kind.exit_status}" in explained.stdout
    assert explained.stdout.count("```") >= 4  # a failing and a fixed example
