"""`rl1c test`: a character per test, failures with the run's story and the command that
replays it, the summary, the exit status (0 all passed, 1 a failure or an error, 2 an
unreadable or invalid test file), the folders searched, and the JUnit XML of --junit."""

from __future__ import annotations

import shlex
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support import EXAMPLES
from support.cli import rl1c

from rl1.compiler.cli.project_template import FILES

# The tutorial's program and a world where it meets a goal, from `rl1c new`'s files.
PROGRAM = FILES["main.rob"]
WORLD = FILES["main.world.toml"]
SENSORS = '"ULT A" = [120, 80, 45, 38]\n'


def project(folder: Path, tests: str) -> Path:
    """A folder with the program, its world and sensor script, and `tests` as t.tests.toml."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "main.rob").write_text(PROGRAM)
    (folder / "main.world.toml").write_text(WORLD)
    (folder / "main.sensors.toml").write_text(SENSORS)
    (folder / "t.tests.toml").write_text(tests)
    return folder / "t.tests.toml"


def table(name: str, **keys: str) -> str:
    """A [[test]] table: name, program main.rob, then `keys` as written (TOML values)."""
    lines = [f'name = "{name}"', 'program = "main.rob"',
             *(f"{key} = {value}" for key, value in keys.items())]
    return "[[test]]\n" + "\n".join(lines) + "\n\n"


ON_SENSORS = {"sensors": '"main.sensors.toml"'}
ON_WORLD = {"world": '"main.world.toml"'}


def test_passing_tests_print_a_dot_each_and_the_summary(tmp_path: Path) -> None:
    file = project(tmp_path, table("ends", **ON_SENSORS, **{"expect.variables": "{ A = -2 }"})
                   + table("goal", **ON_WORLD, **{"expect.goal": '"met"',
                                                  "expect.calls": '["HLD", "MOV 0,0"]'}))
    result = rl1c("test", file)
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0] == f"{file} .."
    assert "FAILURES" not in result.stdout
    assert lines[-1].startswith("=") and " 2 passed in " in lines[-1]


def test_a_failure_tells_the_runs_story_and_how_to_replay_it(tmp_path: Path) -> None:
    file = project(tmp_path, table("ok", **ON_SENSORS)
                   + table("wrong", **ON_SENSORS, **{"expect.variables": "{ A = 5, B = 0 }",
                                                     "expect.calls": '["MOV 9,9", "HLD"]'}))
    result = rl1c("test", file)
    assert result.exit_code == 1
    out = result.stdout
    assert out.splitlines()[0] == f"{file} .F"
    story = out[out.index(f"{file}: wrong"):]
    assert "expected A = 5 (found -2)" in story and "B = 0" not in story
    assert "expected in the trace, but never called: `MOV 9,9`" in story
    assert "the run's last 10 calls (4 before them not shown):" in story
    assert "     2500    10  HLD" in story  # the last call, with its time and line
    assert "the program ended normally" in story and "variables: A=-2" in story
    replay = next(line for line in story.splitlines() if line.startswith("replay: "))
    assert shlex.split(replay[len("replay: "):]) == [
        "rl1c", "run", str(tmp_path / "main.rob"), "--sensors",
        str(tmp_path / "main.sensors.toml")]
    assert out.splitlines()[-1].count("1 passed, 1 failed in ")


def test_a_fault_is_shown_on_its_source_line(tmp_path: Path) -> None:
    file = project(tmp_path, table("no script", **{"expect.ends": '"normally"'}))
    result = rl1c("test", file)
    assert result.exit_code == 1
    assert "expected the run to end normally, but it ended with a fault, device-error" \
        in result.stdout
    assert "error[E1013]: (ULT A) at 600 ms has no reading" in result.stdout
    assert "8 | :10 (TIM 5); A=(ULT A)-40; ?A>#10" in result.stdout
    # The fault expected is a pass.
    file.write_text(table("no script", **{"expect.ends": '"device-error"'}))
    assert rl1c("test", file).exit_code == 0


def test_a_goal_missed_shows_the_verdict_and_the_sim_command(tmp_path: Path) -> None:
    file = project(tmp_path, table("missed", **ON_WORLD, seed="3",
                                   **{"expect.goal": '"missed"'}))
    result = rl1c("test", file)
    assert result.exit_code == 1
    assert 'expected the goal missed, but goal met' in result.stdout
    assert '- end "stopped before the wall": met' in result.stdout
    assert f"replay: rl1c sim {tmp_path / 'main.rob'} --world " \
           f"{tmp_path / 'main.world.toml'} --seed 3" in result.stdout


def test_a_success_rate_below_the_least_fails_with_the_campaigns_summary(
        tmp_path: Path) -> None:
    # A deadline of 20 s: the vehicle stops at about 22.6 s, so every run misses it.
    (tmp_path / "late.world.toml").write_text(WORLD.replace("deadline = 60", "deadline = 20"))
    file = project(tmp_path, table("rate", world='"late.world.toml"',
                                   **{"expect.success": "{ runs = 3, at_least = 0.5 }"}))
    result = rl1c("test", file, "--jobs", "1")
    assert result.exit_code == 1
    out = result.stdout
    assert "expected a success rate of at least 50.0% over 3 runs, but 0 of 3 succeeded" in out
    assert "success: 0 of 3, 0.0%" in out
    assert "goal-missed (deadline): seeds 0, 1, 2" in out
    assert f"replay: rl1c sim {tmp_path / 'main.rob'} --world " \
           f"{tmp_path / 'late.world.toml'} --seed 0" in out  # one failed run
    assert "--runs 3 --seed 0 --jobs 1" in out  # and the campaign


def test_errors_are_an_e_and_do_not_stop_the_other_tests(tmp_path: Path) -> None:
    (tmp_path / "broken.rob").write_text("(MOV 3,3\n")
    (tmp_path / "bad.world.toml").write_text("[floor]\nsize = [1]\n")
    file = project(tmp_path, table("gone", program='"missing.rob"')
                   + table("ok", **ON_SENSORS)
                   + table("bad world", world='"bad.world.toml"')
                   + table("broken", sensors='"main.sensors.toml"'))
    text = file.read_text().replace('program = "main.rob"\nprogram = "missing.rob"',
                                    'program = "missing.rob"')
    text = text.replace('name = "broken"\nprogram = "main.rob"',
                        'name = "broken"\nprogram = "broken.rob"')
    file.write_text(text)
    result = rl1c("test", file)
    assert result.exit_code == 1
    out = result.stdout
    assert out.splitlines()[0] == f"{file} E.EE"
    assert f"cannot read {tmp_path / 'missing.rob'}: no such file" in out
    assert "the world file is not valid" in out and "floor.size" in out
    assert "broken.rob has errors: it cannot run" in out and "error[E0101]" in out
    assert "1 passed, 3 errors in " in out.splitlines()[-1]


def test_an_invalid_test_file_is_refused_with_its_line_before_any_test_runs(
        tmp_path: Path) -> None:
    good = project(tmp_path / "a", table("ok", **ON_SENSORS))
    bad = tmp_path / "b.tests.toml"
    bad.write_text(table("x", **{"expect.goal": '"met"'}))
    result = rl1c("test", good, bad)
    assert result.exit_code == 2
    assert result.stdout == ""
    assert "the test file is not valid: test[0].expect.goal: a goal is judged on a world" \
           in result.stderr
    assert f"\n --> {bad}:4\n" in result.stderr
    assert "Traceback" not in result.output


def test_an_unreadable_test_file_or_a_folder_without_one_is_exit_status_2(
        tmp_path: Path) -> None:
    result = rl1c("test", tmp_path / "none.tests.toml")
    assert result.exit_code == 2
    assert "cannot read the test file" in result.stderr and "no such file" in result.stderr
    result = rl1c("test", tmp_path)
    assert result.exit_code == 2
    assert f"no test file (*.tests.toml) in `{tmp_path}` or below it" in result.stderr


def test_folders_are_searched_in_order_leaving_out_hidden_ones(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    project(tmp_path / "b", table("b", **ON_SENSORS))
    project(tmp_path / "a" / "deep", table("a", **ON_SENSORS))
    project(tmp_path / ".hidden", table("hidden", program='"gone.rob"'))
    (tmp_path / "notes.toml").write_text("not a test file")
    monkeypatch.chdir(tmp_path)
    result = rl1c("test")  # the current folder
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[:2] == ["a/deep/t.tests.toml .", "b/t.tests.toml ."]


def test_junit_xml_has_the_counts_the_cases_and_their_failures(tmp_path: Path) -> None:
    file = project(tmp_path, table("ok", **ON_SENSORS)
                   + table("wrong \\u0001 name", **ON_SENSORS,
                           **{"expect.variables": "{ A = 5 }"})
                   + table("gone", sensors='"gone.toml"'))
    junit = tmp_path / "out" / "junit.xml"
    junit.parent.mkdir()
    result = rl1c("test", file, "--junit", junit)
    assert result.exit_code == 1
    root = ET.fromstring(junit.read_bytes())
    assert root.tag == "testsuites"
    assert {key: root.get(key) for key in ("tests", "failures", "errors", "skipped")} == {
        "tests": "3", "failures": "1", "errors": "1", "skipped": "0"}
    (suite,) = root
    assert suite.tag == "testsuite" and suite.get("name") == str(file)
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("3", "1", "1")
    cases = list(suite)
    assert [case.tag for case in cases] == ["testcase"] * 3
    assert {case.get("classname") for case in cases} == {str(file)}
    # A control character, which XML cannot hold, is replaced.
    assert [case.get("name") for case in cases] == ["ok", "wrong \ufffd name", "gone"]
    for case in cases:
        assert float(case.get("time") or "x") >= 0
    assert [[child.tag for child in case] for case in cases] == [[], ["failure"], ["error"]]
    failure, error = cases[1][0], cases[2][0]
    assert failure.get("message") == "expected A = 5 (found -2)"
    assert "replay: rl1c run" in (failure.text or "")
    assert "the sensor script" in (error.get("message") or "") \
        or "gone.toml" in (error.get("message") or "")
    assert float(root.get("time") or "x") >= float(suite.get("time") or "x") - 0.01
    # Written all at once: no temporary file is left beside it.
    assert [path.name for path in junit.parent.iterdir()] == ["junit.xml"]


def test_junit_to_an_unwritable_place_is_exit_status_2(tmp_path: Path) -> None:
    file = project(tmp_path, table("ok", **ON_SENSORS))
    result = rl1c("test", file, "--junit", tmp_path / "no" / "such" / "junit.xml")
    assert result.exit_code == 2
    assert "cannot write the JUnit file" in result.stderr


@pytest.mark.slow  # forty simulated runs on worker processes, and five more
def test_the_examples_pass() -> None:
    result = rl1c("test", EXAMPLES, "--jobs", "2")
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[0] == f"{EXAMPLES / 'listing1.tests.toml'} ....."


@pytest.mark.parametrize("data", [b"\xff\xfe\x00garbage", b"[[test]]\nname = \"x\"\nprogram = 3\n",
                                  b"[[test]]\n" + b"[" * 5000, b"test = " + b"9" * 5000])
def test_a_hostile_test_file_is_exit_status_2_without_a_traceback(
        tmp_path: Path, data: bytes) -> None:
    file = tmp_path / "h.tests.toml"
    file.write_bytes(data)
    result = rl1c("test", file)
    assert result.exit_code == 2
    assert "the test file is not valid: " in result.stderr
    assert f"\n --> {file}" in result.stderr
    assert "Traceback" not in result.output and "internal error" not in result.output


def test_a_folder_named_as_the_program_is_an_error(tmp_path: Path) -> None:
    file = project(tmp_path, table("folder", **ON_SENSORS))
    file.write_text(file.read_text().replace('"main.rob"', '"sub"'))
    (tmp_path / "sub").mkdir()
    result = rl1c("test", file)
    assert result.exit_code == 1
    assert "it is a directory" in result.stdout


def test_an_ilc_program_runs_and_a_refused_one_is_an_error(tmp_path: Path) -> None:
    file = project(tmp_path, table("compiled", program='"main.ilc"', **ON_SENSORS,
                                   **{"expect.variables": "{ A = -2 }"})
                   + table("refused", program='"bad.ilc"', **ON_SENSORS))
    text = file.read_text().replace('program = "main.rob"\n', "", 2)
    file.write_text(text)
    assert rl1c("compile", tmp_path / "main.rob", "-o", tmp_path / "main.ilc").exit_code == 0
    (tmp_path / "bad.ilc").write_bytes(b"RL1I\x00garbage")
    result = rl1c("test", file)
    assert result.exit_code == 1
    assert result.stdout.splitlines()[0] == f"{file} .E"
    assert f"{tmp_path / 'bad.ilc'} is not valid intermediate code: byte " in result.stdout


def test_a_goal_expected_of_a_world_without_one_is_an_error(tmp_path: Path) -> None:
    (tmp_path / "plain.world.toml").write_text(WORLD.split("[goal]")[0])
    file = project(tmp_path, table("no goal", world='"plain.world.toml"',
                                   **{"expect.goal": '"met"'}))
    result = rl1c("test", file)
    assert result.exit_code == 1
    assert "has no [goal] to judge: add one" in result.stdout


@st.composite
def mutated(draw: st.DrawFn, text: bytes) -> bytes:
    """`text` with a few bytes flipped, inserted, deleted or cut off."""
    data = bytearray(text)
    for _ in range(draw(st.integers(1, 6))):
        at = draw(st.integers(0, max(len(data) - 1, 0)))
        match draw(st.sampled_from(["flip", "insert", "delete", "cut"])):
            case "flip" if data:
                data[at] ^= 1 << draw(st.integers(0, 7))
            case "insert":
                data[at:at] = draw(st.binary(min_size=1, max_size=8))
            case "delete":
                del data[at:at + draw(st.integers(1, 8))]
            case _:
                del data[at:]
    return bytes(data)


HOSTILE_BASE = (table("on the script", **ON_SENSORS, **{"expect.variables": "{ A = -2 }",
                                                        "expect.calls": '["ULT A"]'})
                + table("no script", **{"expect.ends": '"device-error"'})).encode()


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=mutated(HOSTILE_BASE), sensors=mutated(SENSORS.encode()))
def test_mutated_test_files_and_scripts_never_crash(tmp_path: Path, data: bytes,
                                                     sensors: bytes) -> None:
    file = project(tmp_path, "")
    file.write_bytes(data)
    (tmp_path / "main.sensors.toml").write_bytes(sensors)
    result = rl1c("test", file, "--junit", tmp_path / "junit.xml")
    assert result.exit_code in (0, 1, 2), result.output
    assert "Traceback" not in result.output and "internal error" not in result.output
    if result.exit_code != 2:
        ET.fromstring((tmp_path / "junit.xml").read_bytes())  # well-formed, whatever the names
