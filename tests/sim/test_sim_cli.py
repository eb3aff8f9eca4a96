"""`rl1c sim`: its report, its pictures, its exit statuses, and a clear message (never a
traceback) for a bad world file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.cli import rl1c

EXAMPLES = Path(__file__).parents[2] / "examples"
SAMPLE = EXAMPLES / "sample.rob"
WORLD = EXAMPLES / "sample.world.toml"


def test_text_report_has_calls_poses_ending_and_variables() -> None:
    result = rl1c("sim", SAMPLE, "--world", WORLD)
    assert result.exit_code == 0, result.output
    assert "CAM P 579" in result.stdout
    assert "(  236.4,   150.0)" in result.stdout  # the pose at the branch mark
    assert "the program ended normally" in result.stdout
    assert "C=579 D=450" in result.stdout


def test_a_vehicle_moving_at_the_end_runs_on_until_it_stops(tmp_path: Path) -> None:
    program, picture = tmp_path / "away.rob", tmp_path / "away.svg"
    program.write_text("(MOV 6,6)\n(END)\n")
    result = rl1c("sim", program, "--world", WORLD, "--format", "json", "--svg", picture)
    assert result.exit_code == 0, result.output  # the program itself ended normally
    report = json.loads(result.stdout)
    # 30 cm/s from x = 60 until the front corners (40 cm ahead) pass x = 800: found at
    # most one step (0.05 s) late.
    assert report["run_on"]["stop"] == "off-floor"
    assert 700 / 30 <= report["run_on"]["seconds"] <= 700 / 30 + 0.05
    assert report["track"][-1][1] == pytest.approx(760, abs=1.5)
    assert [event["kind"] for event in report["events"]] == ["end", "fault"]
    assert "it runs on" in picture.read_text() and "left the floor" in picture.read_text()
    text = rl1c("sim", program, "--world", WORLD).stdout
    assert "with the vehicle moving: it ran on for 23.3" in text


def test_a_vehicle_standing_at_the_end_does_not_run_on() -> None:
    report = json.loads(rl1c("sim", SAMPLE, "--world", WORLD, "--format", "json").stdout)
    assert report["run_on"] is None
    assert report["events"][-1]["kind"] == "end"


def test_json_report_has_the_track_and_is_deterministic(tmp_path: Path) -> None:
    noisy = tmp_path / "noisy.toml"
    noisy.write_text(WORLD.read_text() + "\n[noise]\nimage_px = 0.3\nodometry = 0.01\n")
    runs = [json.loads(rl1c("sim", SAMPLE, "--world", world, "--format", "json",
                            "--seed", seed).stdout)
            for world, seed in ((WORLD, "1"), (WORLD, "2"), (noisy, "7"), (noisy, "7"),
                                (noisy, "8"))]
    assert runs[0]["status"] == "ok"
    assert runs[0]["track"][0] == [0.0, 60.0, 150.0, 0.0]
    assert {"time", "call", "args", "pose"} <= set(runs[0]["trace"][0])
    assert runs[0] == runs[1]  # noise is off by default: the seed changes nothing
    assert runs[2] == runs[3]  # the same seed, the same run
    assert runs[2]["trace"] != runs[4]["trace"]  # another seed, other readings


def test_pictures_are_written(tmp_path: Path) -> None:
    svg, html = tmp_path / "run.svg", tmp_path / "run.html"
    result = rl1c("sim", SAMPLE, "--world", WORLD, "--svg", svg, "--html", html)
    assert result.exit_code == 0, result.output
    picture = svg.read_text()
    assert picture.startswith("<svg") and "the program ended" in picture
    page = html.read_text()
    assert "<svg" in page and '"track": [[0.0, 60.0, 150.0, 0.0]' in page
    assert "http" not in page.replace("http://www.w3.org/2000/svg", "")  # offline


def test_a_safety_stop_is_a_device_fault_with_its_line(tmp_path: Path) -> None:
    program = tmp_path / "runaway.rob"
    program.write_text("(MOV 12,12)\n:10 (IMG)\n#10\n")
    result = rl1c("sim", program, "--world", WORLD, "--format", "json")
    assert result.exit_code == 13
    status = json.loads(result.stdout)["status"]
    assert status["safety"] == "off-floor" and status["line"] == 2


def test_a_bad_world_file_is_a_message_and_status_2(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(WORLD.read_text().replace("facing = -137.0663", 'facing = "north"'))
    result = rl1c("sim", SAMPLE, "--world", bad)
    assert result.exit_code == 2
    assert f"{bad}:41: stands[0].facing: expected a number" in result.stderr
    assert "Traceback" not in result.output
    missing = rl1c("sim", SAMPLE, "--world", tmp_path / "none.toml")
    assert missing.exit_code == 2 and "Traceback" not in missing.output


def test_an_ilc_file_runs_on_the_vm(tmp_path: Path) -> None:
    ilc = tmp_path / "sample.ilc"
    assert rl1c("compile", SAMPLE, "-o", ilc).exit_code == 0
    from_ilc = rl1c("sim", ilc, "--world", WORLD)
    assert from_ilc.exit_code == 0
    assert from_ilc.stdout == rl1c("sim", SAMPLE, "--world", WORLD).stdout


def test_the_readme_picture_is_the_one_the_command_draws(tmp_path: Path) -> None:
    svg = tmp_path / "sample.svg"
    assert rl1c("sim", SAMPLE, "--world", WORLD, "--svg", svg).exit_code == 0
    assert svg.read_text() == (EXAMPLES / "sample.svg").read_text(), (
        "regenerate it: rl1c sim examples/sample.rob --world examples/sample.world.toml "
        "--svg examples/sample.svg")


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.sampled_from([
    "(MOV 3,3)", "(MVI 2,2,30)", "(ROT 90)", "(STX 450)", "(STL 75)", "(TRC 3)", "(TRC 2)",
    "(CAM D)", "(CAM U)", "(CAM P 500)", "(SCN 0)", "(SCN 2)", "A=(IMG)", "B=(ULT A)",
    "C=(KYO)", "(KYC)", "(TIM 5)", "(MOV 0,0)", "(FRE)", "(INP 3)", "(FZI)", ":10", "#10",
    "?A>#10", ":96", ":98",
]), max_size=12))
def test_any_program_ends_with_a_known_status_and_no_traceback(tmp_path: Path,
                                                                statements: list[str]) -> None:
    program = tmp_path / "any.rob"
    program.write_text("\n".join(statements) + "\n(END)\n")
    result = rl1c("sim", program, "--world", WORLD, "--budget", "20000", "--format", "json")
    assert result.exit_code in (0, 1, 10, 11, 12, 13), result.output
    assert "Traceback" not in result.output
