"""One error style in every command: a file that cannot be read, written or used is an
E0100 diagnostic that names the file's role (source file, .ilc file, sensor script,
world file, rl1.toml, output), printed as the checker prints any diagnostic, with what
to do, and the exit status the command documents."""

from pathlib import Path

import pytest
from support import EXAMPLES, SAMPLE
from support.cli import rl1c

WORLD = EXAMPLES / "sample.world.toml"


def problem(output: str) -> tuple[str, str]:
    """The E0100 block in `output`: its first line, and its help."""
    block = output[output.index("error[E0100]: "):]
    first = block.splitlines()[0]
    helps = [line for line in block.splitlines() if "= help: " in line]
    return first, helps[0].split("= help: ")[1] if helps else ""


def cases(tmp: Path) -> list[tuple[list[str | Path], int, str]]:
    """Each command with a file of each role it takes that cannot be read, written or
    used: its arguments, exit status and the start of its E0100 message."""
    gone, folder = tmp / "gone", tmp / "dir"
    compiled, bad = tmp / "p.ilc", tmp / "bad"
    return [
        (["compile", gone / "p.rob"], 2, f"cannot read the source file `{gone / 'p.rob'}`"),
        ([SAMPLE, "-o", folder], 2, f"cannot write the output file `{folder}`"),
        (["check", gone / "p.rob"], 2, f"cannot read the source file `{gone / 'p.rob'}`"),
        (["fmt", gone / "p.rob"], 2, f"cannot read the source file `{gone / 'p.rob'}`"),
        (["dis", gone / "p.ilc"], 2,
         f"cannot read the intermediate code file `{gone / 'p.ilc'}`"),
        (["dis", bad / "p.ilc"], 1, f"the intermediate code file `{bad / 'p.ilc'}` is not "
         "valid: it is text, not compiled code"),
        (["dis", compiled, "--source", gone / "p.rob"], 2,
         f"cannot read the --source file `{gone / 'p.rob'}`"),
        (["asm", gone / "p.ils"], 2, f"cannot read the .ils file `{gone / 'p.ils'}`"),
        (["asm", bad / "p.ils", "-o", folder], 2, f"cannot write the output file `{folder}`"),
        (["run", gone / "p.rob"], 2, f"cannot read the source file `{gone / 'p.rob'}`"),
        (["run", gone / "p.ilc"], 2,
         f"cannot read the intermediate code file `{gone / 'p.ilc'}`"),
        (["run", SAMPLE, "--sensors", gone / "s.json"], 2,
         f"cannot read the sensor script `{gone / 's.json'}`"),
        (["run", SAMPLE, "--sensors", bad / "s.json"], 2,
         "the sensor script is not valid: "),
        (["sim", gone / "p.rob", "--world", WORLD], 2,
         f"cannot read the source file `{gone / 'p.rob'}`"),
        (["sim", SAMPLE, "--world", gone / "w.toml"], 2,
         f"cannot read the world file `{gone / 'w.toml'}`"),
        (["sim", SAMPLE, "--world", bad / "w.toml"], 2,
         "the world file is not valid: "),
        (["sim", SAMPLE, "--world", WORLD, "--svg", folder], 2,
         f"cannot write the SVG file `{folder}`"),
        (["sim", SAMPLE, "--world", WORLD, "--html", folder], 2,
         f"cannot write the HTML file `{folder}`"),
        (["check", bad / "p.rob"], 2, "the project file is not valid: "),
    ]


@pytest.fixture
def files(tmp_path: Path) -> Path:
    (tmp_path / "dir").mkdir()
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "p.ilc").write_bytes(b"not an ilc file")
    (bad / "p.ils").write_text("END\n")
    (bad / "p.rob").write_text("(END)\n")
    (bad / "s.json").write_text('{"IMG": 3}')
    (bad / "w.toml").write_text("[floor\n")
    (bad / "rl1.toml").write_text("[lint]\n")
    assert rl1c(SAMPLE, "-o", tmp_path / "p.ilc").exit_code == 0
    return tmp_path


def test_every_command_names_the_role_of_a_file_it_cannot_use(files: Path) -> None:
    for args, status, message in cases(files):
        result = rl1c(*args)
        assert result.exit_code == status, (args, result.output)
        first, help_text = problem(result.output)
        assert first.startswith(f"error[E0100]: {message}"), (args, first)
        assert help_text, (args, result.stderr)  # and what to do
        assert "Traceback" not in result.output


def test_a_file_problem_is_shown_as_the_checker_shows_e0100(files: Path) -> None:
    sensors = files / "gone" / "s.json"
    result = rl1c("run", SAMPLE, "--sensors", sensors)
    assert result.stderr == (f"error[E0100]: cannot read the sensor script `{sensors}`: no such "
                             f"file\n --> {sensors}\n  |\n  = help: check the name, and the "
                             "folder rl1c runs in\n")
    checked = rl1c("check", files / "gone" / "p.rob").stdout
    assert checked.startswith(f"error[E0100]: cannot read the source file "
                              f"`{files / 'gone' / 'p.rob'}`: no such file\n --> ")
