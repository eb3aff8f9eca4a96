"""Messages that say one thing the same way wherever it is said, as a user meets them
through `rl1c`: a fault's help said once, whichever engine meets it."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from support.cli import rl1c

from rl1.compiler.cli import fuzz
from rl1.compiler.cli.sim_campaign import Progress

LOOP = ":10 A=A+1\n#10\n(END)\n"


@pytest.mark.parametrize(("engine", "counted"), [("vm", "instructions"),
                                                 ("ast", "statements")])
def test_a_used_up_budget_says_what_to_do_once_whichever_engine_runs(
    tmp_path: Path, engine: str, counted: str
) -> None:
    (tmp_path / "loop.rob").write_text(LOOP)
    result = rl1c("run", tmp_path / "loop.rob", "--budget", "100", "--engine", engine)
    assert result.exit_code == 12
    assert f"error[E1012]: the program ran more than 100 {counted} without ending\n" \
           in result.stdout
    assert result.stdout.count("raise") == 1  # the help alone says to raise the budget
    assert "= help: if the program should run longer, raise --budget;" in result.stdout


@pytest.mark.parametrize("args", [["explain", "E9999"], ["docs", "nothing-such"]])
def test_a_command_that_fails_names_itself_as_its_usage_errors_do(args: list[str]) -> None:
    failed = rl1c(*args)
    misused = rl1c(args[0], "--bogus")
    assert failed.exit_code == misused.exit_code == 2
    # Both say `rl1c explain: error: ...`, the command that failed named first.
    assert misused.stderr.splitlines()[-1].startswith(f"rl1c {args[0]}: error: ")
    assert failed.stderr.startswith(f"rl1c {args[0]}: error: `")


def test_rl1c_new_says_its_errors_once_named(tmp_path: Path) -> None:
    (tmp_path / "taken").write_text("")
    failed = rl1c("new", tmp_path / "taken")
    assert failed.stderr == (f"rl1c new: error: `{tmp_path / 'taken'}` exists and is no "
                             "folder; give the path of a new folder\n")


def test_a_note_names_the_command_as_its_errors_do(tmp_path: Path) -> None:
    (tmp_path / "p.rob").write_text("(END)\n")
    (tmp_path / "w.toml").write_text("[floor]\nsize = [600, 400]\n[start]\nx = 100.0\n"
                                     "y = 200.0\n[vary]\nstart.heading = { uniform = [5, 5] }\n")
    ran = rl1c("sim", tmp_path / "p.rob", "--world", tmp_path / "w.toml", "--seed", "3")
    assert ran.exit_code == 0, ran.output
    # Where it said `rl1c: note:` beside `rl1c sim: error: ...`.
    assert ran.stderr == "rl1c sim: note: the world of seed 3: start.heading = 5\n"


def test_a_campaigns_warning_names_its_command_as_its_errors_do() -> None:
    warned = {"rl1c sim": io.StringIO(), "rl1c fuzz": io.StringIO()}
    Progress(10, warned["rl1c sim"]).warn("a worker was lost")
    fuzz._Bar(10, None, warned["rl1c fuzz"]).warn("a worker was lost")
    # Where both said `rl1c: warning:` and their errors `rl1c fuzz: error:`.
    for command, stream in warned.items():
        assert stream.getvalue() == f"{command}: warning: a worker was lost\n"


def test_every_configuration_file_is_named_once_and_placed_at_its_line(
    tmp_path: Path,
) -> None:
    (tmp_path / "p.rob").write_text("(MOV 3,3)\nA=(IMG)\n(END)\n")
    script = tmp_path / "s.json"
    script.write_text('{\n  "comment": "",\n  "readings": 1\n}\n')
    world = tmp_path / "w.toml"
    world.write_text("[floor]\nwidht = 3\n")
    project = tmp_path / "rl1.toml"
    project.write_text('[check]\nselect = ["W"]\nignre = ["W0603"]\n')
    said = [rl1c("run", tmp_path / "p.rob", "--sensors", script).stderr,
            rl1c("sim", tmp_path / "p.rob", "--world", world).stderr,
            rl1c("check", tmp_path / "p.rob").stderr]
    assert [text.splitlines()[:2] for text in said] == [
        ["error[E0100]: the sensor script is not valid: readings: unknown key; expected one "
         'of "IMG", "KYO", "CAM R", "ULT A", "ULT B", "ULT C", "ULT D", "INP", "FZI", '
         '"line_lost", "fail", "stop_fails", "after_last", "comment"', f" --> {script}:3"],
        ["error[E0100]: the world file is not valid: floor.widht: unknown key; expected one "
         "of size", f" --> {world}:2"],
        ["error[E0100]: the project file is not valid: check.ignre: unknown key; did you "
         "mean ignore? (expected one of select, ignore, warnings-as-errors)",
         f" --> {project}:3"],  # where rl1.toml said `line 3:`
    ]
    for text, file in zip(said, (script, world, project), strict=True):
        assert text.count(str(file)) == 1


@pytest.mark.parametrize("character", ["\ue000", "\U000f8f3f", "\u0378"])  # private, unassigned
def test_a_character_a_terminal_shows_as_nothing_is_shown_by_its_code_point_in_the_snippet(
    tmp_path: Path, character: str
) -> None:
    (tmp_path / "p.rob").write_text(f"A=1\nB={character}\n(END)\n")
    out = rl1c("check", tmp_path / "p.rob", "--color", "never").stdout
    code = f"U+{ord(character):04X}"
    # Named as E0102 names it, and underlined whole: the caret line counts its cells.
    assert f"error[E0102]: unexpected character {code}\n" in out
    assert f"2 | B=<{code}>\n  |   {'^' * len(f'<{code}>')}\n" in out
