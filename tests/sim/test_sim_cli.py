"""`rl1c sim`: its report, its pictures, its exit statuses, and a clear message (never a
traceback) for a bad world file."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.cli import rl1c

EXAMPLES = Path(__file__).parents[2] / "examples"
SAMPLE = EXAMPLES / "sample.rob"
WORLD = EXAMPLES / "sample.world.toml"


def test_text_report_has_calls_poses_ending_and_variables() -> None:
    result = rl1c("sim", SAMPLE, "--world", WORLD, "--trace", "all")
    assert result.exit_code == 0, result.output
    assert "CAM P 579" in result.stdout
    assert "(  236.5,   150.0)" in result.stdout  # the pose at the branch mark
    assert "the program ended normally" in result.stdout
    assert "C=579 D=450" in result.stdout


def test_a_vehicle_moving_at_the_end_runs_on_until_it_stops(tmp_path: Path) -> None:
    program, picture = tmp_path / "away.rob", tmp_path / "away.svg"
    program.write_text("(MOV 6,6)\n(END)\n")
    result = rl1c("sim", program, "--world", WORLD, "--format", "json", "--svg", picture)
    assert result.exit_code == 20, result.output  # it ended normally, but off the goal
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
    assert runs[0]["status"]["code"] == "ok"
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
    assert (status["code"], status["exit_status"]) == ("device-error", 13)  # run's shape
    text = rl1c("sim", program, "--world", WORLD).stdout
    assert "error[E1013]: " in text  # shown as `rl1c run` shows a fault
    assert f"\n --> {program}:2:5\n" in text and "\n2 | :10 (IMG)\n" in text


def test_a_bad_world_file_is_a_message_and_status_2(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(WORLD.read_text().replace("facing = -137.0663", 'facing = "north"'))
    result = rl1c("sim", SAMPLE, "--world", bad)
    assert result.exit_code == 2
    assert "is not valid: stands[0].facing: expected a number" in result.stderr
    assert f"  --> {bad}:41\n" in result.stderr
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
    assert result.exit_code in (0, 1, 10, 11, 12, 13, 20), result.output  # 20: goal missed
    assert "Traceback" not in result.output
    if result.exit_code != 1:  # it ran: the text ends with what the JSON says
        document = json.loads(result.stdout)
        count = document["instructions"]
        text = rl1c("sim", program, "--world", WORLD, "--budget", "20000", "--trace", "none")
        assert text.stdout.splitlines()[-1] == (
            f"{document['device_time']} ms of device time, {count:,} "
            f"instruction{'s' if count != 1 else ''}")


def test_the_trace_is_bounded_as_rl1c_run_bounds_it() -> None:
    every = rl1c("sim", SAMPLE, "--world", WORLD, "--trace", "all").stdout.splitlines()
    short = rl1c("sim", SAMPLE, "--world", WORLD).stdout.splitlines()
    calls = [line for line in every[1:] if line.startswith("  ") and "[" not in line]
    assert short[1:41] == calls[:40]
    assert short[41].split()[:2] == ["...", f"({len(calls) - 60:,}"]
    assert short[42:62] == calls[-20:]
    assert short[62:] == every[len(calls) + 1:]  # the events, the ending, the variables
    document = json.loads(rl1c("sim", SAMPLE, "--world", WORLD, "--format", "json",
                               "--trace", "short").stdout)
    assert len(document["trace"]) == 60
    assert document["trace_left_out"] == {"after": 40, "count": len(calls) - 60}
    none = rl1c("sim", SAMPLE, "--world", WORLD, "--trace", "none").stdout
    assert not none.startswith("trace") and "the program ended normally" in none


def test_run_and_sim_report_alike(tmp_path: Path) -> None:
    """The same columns (device time in ms when each call was made, source line), the
    readings named, and the same last lines: variables, device time, instructions."""
    program, world = tmp_path / "p.rob", tmp_path / "w.toml"
    program.write_text("(TIM 5)\nA=(KYO); (MOV 0,0)\n(END)\n")
    # The scripted device's calls take no time between them: nor, to the ms, do these.
    world.write_text("[floor]\nsize = [800, 500]\n[start]\nx = 60\ny = 150\n"
                     "[vehicle]\ninstruction_time = 1e-5\n")
    ran = rl1c("run", program, "--sensors", _script(tmp_path)).stdout.splitlines()
    simulated = rl1c("sim", program, "--world", world).stdout.splitlines()
    assert ran[0] == simulated[0][:len(ran[0])] == "  time ms  line  call"
    assert [line.split()[:3] for line in simulated[1:4]] == [
        ["0", "1", "TIM"], ["500", "2", "KYO"], ["500", "2", "MOV"]]
    assert [line.split()[:3] for line in ran[1:4]] == [line.split()[:3]
                                                        for line in simulated[1:4]]
    assert simulated[2].split("(")[0].rstrip().endswith("KYO -> centre 0, right 0, left 0")
    assert ran[-3:] == simulated[-3:] == [
        "the program ended normally", "variables: all 0",
        "500 ms of device time, 6 instructions"]
    document = json.loads(rl1c("sim", program, "--world", world, "--format", "json").stdout)
    assert (document["device_time"], document["instructions"]) == (500, 6)
    assert [entry["line"] for entry in document["trace"]] == [1, 2, 2]


def _script(tmp_path: Path) -> Path:
    script = tmp_path / "s.json"
    script.write_text(json.dumps({"KYO": [{"centre": 0, "right": 0, "left": 0}]}))
    return script


def test_without_a_world_it_says_what_to_give() -> None:
    result = rl1c("sim", SAMPLE)
    assert result.exit_code == 2
    assert result.stderr.splitlines()[-1] == (
        "rl1c sim: error: a simulation needs a world to run in: give --world FILE, a world "
        "file (TOML, spec/simulator.md) such as examples/sample.world.toml")


@pytest.mark.parametrize("option", ["--svg", "--html"])
def test_a_picture_is_not_written_to_standard_output(tmp_path: Path, option: str) -> None:
    result = rl1c("sim", SAMPLE, "--world", WORLD, option, "-")
    assert result.exit_code == 2 and result.stdout == ""
    assert (f"{option} writes a file, and standard output carries the report: give "
            f"{option} FILE") in result.stderr
    assert not Path("-").exists()


def test_a_read_only_picture_is_replaced_only_with_force(tmp_path: Path) -> None:
    picture = tmp_path / "run.svg"
    picture.write_text("old")
    picture.chmod(0o444)
    refused = rl1c("sim", SAMPLE, "--world", WORLD, "--svg", picture)
    assert refused.exit_code == 2 and "--force" in refused.stderr
    assert picture.read_text() == "old"
    forced = rl1c("sim", SAMPLE, "--world", WORLD, "--svg", picture, "--force")
    assert forced.exit_code == 0, forced.output
    assert picture.read_text().startswith("<svg")


@pytest.mark.parametrize("command", ["run", "sim"])
def test_color_is_asked_for_as_in_the_other_commands(tmp_path: Path, command: str) -> None:
    program = tmp_path / "p.rob"
    program.write_text("(MVI 3,-3,10)\n(END)\n")
    world = ["--world", str(WORLD)] if command == "sim" else []
    colored = rl1c(command, program, *world, "--color", "always")
    plain = rl1c(command, program, *world, "--color", "never")
    assert colored.exit_code == plain.exit_code == 13
    assert "\x1b[" in colored.stdout and "\x1b[" not in plain.stdout
    assert "error[E1013]" in plain.stdout


@pytest.mark.needs_cc
def test_the_c_vm_drives_the_simulator_as_the_reference_does(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))  # a build of its own
    reference = rl1c("sim", SAMPLE, "--world", WORLD, "--format", "json")
    native = rl1c("sim", SAMPLE, "--world", WORLD, "--format", "json", "--engine", "c")
    assert (native.exit_code, native.stdout) == (reference.exit_code, reference.stdout)
    assert json.loads(native.stdout)["trace"][0]["line"] == 2  # lines from the C VM too


def test_json_headings_are_wrapped_to_the_documented_range(tmp_path: Path) -> None:
    program = tmp_path / "turns.rob"
    program.write_text("(ROT 360); (ROT 60); (ROT 135); (ROT -360); (ROT -20)\n(END)\n")
    report = json.loads(rl1c("sim", program, "--world", WORLD, "--format", "json").stdout)
    # After each turn: 360, 420, 555, 195 and 175 degrees from the start's 0.
    assert [entry["pose"][2] for entry in report["trace"]] == [0.0, 60.0, -165.0, -165.0,
                                                               175.0]
    assert all(-180 < heading <= 180 for *_, heading in report["track"])
    text = rl1c("sim", program, "--world", WORLD, "--trace", "all").stdout
    assert " 175.0\n" in text and "420.0" not in text


@pytest.mark.parametrize("engine", ["vm", "ast"])
def test_json_trace_entries_carry_the_source_lines_the_text_shows(engine: str) -> None:
    text = rl1c("sim", SAMPLE, "--world", WORLD, "--trace", "all", "--engine", engine).stdout
    report = json.loads(rl1c("sim", SAMPLE, "--world", WORLD, "--format", "json",
                             "--engine", engine).stdout)
    rows = [line.split() for line in text.splitlines()[1:len(report["trace"]) + 1]]
    assert [entry["line"] for entry in report["trace"]] == [int(row[1]) for row in rows]
    assert all(isinstance(entry["line"], int) for entry in report["trace"])


def test_line_events_are_trace_entries_in_time_order_chosen_by_trace(tmp_path: Path) -> None:
    """A line lost while the program waits shows among the calls at its time, as `rl1c
    run` shows a lost line; `--trace calls` and `none` leave it out (they printed it after
    the last call, out of time order, even with `--trace none`)."""
    program, world = tmp_path / "p.rob", tmp_path / "w.toml"
    program.write_text("(CAM D); (TRC 1); (MOV 4,4)\n:10 (TIM 5); A=(ULT A)-40; ?A>#10\n"
                       "(MOV 0,0); (HLD); (END)\n")
    # Put down 13 degrees off its line, the vehicle loses it within a few centimetres.
    world.write_text("[floor]\nsize = [600, 300]\n[start]\nx = 60\ny = 150\nheading = -13\n"
                     "[[lines]]\npoints = [[0, 150], [600, 150]]\n")
    every = rl1c("sim", program, "--world", world, "--trace", "all").stdout.splitlines()
    rows = [line for line in every[1:] if re.match(r" +\d+ +(\d+|-) ", line)]
    lost = [index for index, line in enumerate(rows) if "[line lost during MOV in mode 1]" in line]
    assert len(lost) == 1 and 0 < lost[0] < len(rows) - 1, every
    times = [int(line.split()[0]) for line in rows]
    assert times == sorted(times), every
    for choice in ("calls", "none"):
        shown = rl1c("sim", program, "--world", world, "--trace", choice).stdout
        assert "[line lost" not in shown, (choice, shown)
