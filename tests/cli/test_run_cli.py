"""`rl1c run`: the reports (text and JSON), the exit status of each outcome, .rob and .ilc
inputs on both engines, and bad input of every kind reported without a traceback."""

import json
from pathlib import Path
from typing import Any

import pytest
from support import SAMPLE, SAMPLE_SENSORS
from support.cli import rl1c

from rl1.vm.language import VARIABLES

SENSORS = SAMPLE_SENSORS


def report(*args: str | Path) -> tuple[int, dict[str, Any]]:
    result = rl1c("run", *args, "--format", "json")
    return result.exit_code, json.loads(result.stdout)


def test_the_sample_runs_its_main_path_and_prints_trace_and_variables() -> None:
    result = rl1c("run", SAMPLE, "--sensors", SENSORS)
    assert result.exit_code == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == "trace (device time in ms):"
    assert lines[1].split() == ["0", "CAM", "Z"]
    assert "IMG -> 185 128 90 0" in result.stdout
    assert [line.split() for line in lines[-6:-2]] == [
        ["3200", "MVI", "1,1,50"], ["13200", "MOV", "3,3"], ["13200", "MOV", "0,0"],
        ["13200", "FRE"]]  # the MVI takes 10 s: 50 cm at 5 cm/s
    assert lines[-2] == "the program ended normally"
    assert lines[-1].startswith("variables: A=5 C=589 D=450 L=100 U=160 ")


def test_json_has_status_every_variable_and_the_trace_and_both_engines_agree() -> None:
    status, vm = report(SAMPLE, "--sensors", SENSORS)
    ast_status, interpreted = report(SAMPLE, "--sensors", SENSORS, "--engine", "ast")
    assert (status, ast_status) == (0, 0)
    assert vm == interpreted
    assert vm["status"] == "ok"
    assert list(vm["variables"]) == list(VARIABLES)
    assert vm["variables"]["@"] == 0 and vm["variables"]["C"] == 589
    assert vm["trace"][0] == {"time": 0, "call": "CAM Z", "args": []}
    assert vm["trace"][6] == {"time": 300, "call": "IMG", "args": [],
                              "result": [120, 128, 90, 0]}


def test_a_compiled_ilc_runs_as_its_source(tmp_path: Path) -> None:
    compiled = tmp_path / "sample.ilc"
    assert rl1c(SAMPLE, "-o", compiled).exit_code == 0
    assert report(compiled, "--sensors", SENSORS) == report(SAMPLE, "--sensors", SENSORS)


@pytest.mark.parametrize(("source", "sensors", "code", "status", "line"), [
    ("(MOV 3,3)\nS=13\n(MOV S,0)\n", None, "argument-range", 10, 3),
    ("(TRC 2)\n(MOV 1,1)\n(TIM 10)\n", {"line_lost": [{"time": 300}]},
     "missing-handler", 11, 3),
    (":10 A++\n#10\n", None, "budget", 12, 2),
    ("(MVI 3,-3,10)\n", None, "device-error", 13, 1),
])
@pytest.mark.parametrize("engine", ["vm", "ast"])
def test_each_fault_kind_has_its_exit_status(
    tmp_path: Path, source: str, sensors: dict[str, Any] | None, code: str, status: int,
    line: int, engine: str,
) -> None:
    program = tmp_path / "p.rob"
    program.write_text(source)
    options = ["--engine", engine, "--budget", "50"]
    if sensors is not None:
        (tmp_path / "s.json").write_text(json.dumps(sensors))
        options += ["--sensors", str(tmp_path / "s.json")]
    exit_code, document = report(program, *options)
    assert exit_code == status
    assert document["status"]["code"] == code
    assert document["status"]["line"] == line
    assert document["trace"][-1]["call"] == "STOP"
    text = rl1c("run", program, *options)
    assert text.exit_code == status
    assert f"fault[{code}] at line {line}: " in text.stdout


def test_toml_sensors_work_like_json(tmp_path: Path) -> None:
    (tmp_path / "s.toml").write_text('"ULT A" = [150]\n')
    (tmp_path / "p.rob").write_text("D=(ULT A)\n")
    exit_code, document = report(tmp_path / "p.rob", "--sensors", tmp_path / "s.toml")
    assert (exit_code, document["variables"]["D"]) == (0, 150)


def test_without_sensors_everything_reads_zero(tmp_path: Path) -> None:
    (tmp_path / "p.rob").write_text("A=(IMG)+1\n")
    exit_code, document = report(tmp_path / "p.rob")
    assert (exit_code, document["variables"]["A"], document["variables"]["w"]) == (0, 1, 0)


def test_bad_inputs_are_reported_without_a_traceback(tmp_path: Path) -> None:
    (tmp_path / "bad.json").write_text('{"IMG": [{"area": 1}]}')
    (tmp_path / "errors.rob").write_text("A=(MOV 1,1)\n")
    compiled = tmp_path / "sample.ilc"
    rl1c(SAMPLE, "-o", compiled)
    (tmp_path / "cut.ilc").write_bytes(compiled.read_bytes()[:30])
    cases = [
        (("run", SAMPLE, "--sensors", tmp_path / "bad.json"), 2,
         'bad.json:IMG[0]: missing "x", "y", "z"'),
        (("run", SAMPLE, "--sensors", tmp_path / "none.json"), 2, "none.json: no such file"),
        (("run", tmp_path / "errors.rob"), 1, "returns no value"),
        (("run", tmp_path / "errors.rob", "--engine", "ast"), 1, "returns no value"),
        (("run", tmp_path / "none.rob"), 2, "no such file"),
        (("run", tmp_path / "cut.ilc"), 1, "cut.ilc: byte 30: truncated"),
        (("run", tmp_path / "none.ilc"), 2, "cannot read"),
        (("run", compiled, "--engine", "ast"), 2, "an .ilc file runs on the VM"),
        (("run", SAMPLE, "--budget", "0"), 2, "--budget"),
        (("run", SAMPLE, "--budget", str(2**31)), 2, "from 1 to 2147483647"),
    ]
    for args, status, message in cases:
        result = rl1c(*args)
        assert result.exit_code == status, (args, result.output)
        assert message in result.stderr, (args, result.stderr)
        assert result.stdout == "" and "Traceback" not in result.output
