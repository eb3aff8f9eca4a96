"""Messages read side by side, as a user meets them through `rl1c check`, `rl1c run` and
`rl1c sim`: each says what is wrong, where, and what to do, in the terms of the file at
hand, and says the same kind of thing the same way wherever it is said."""

from __future__ import annotations

import json
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st
from support.cli import rl1c

from rl1.vm import ilc
from rl1.vm.config import unknown_key

PROGRAM = "(MOV 3,3)\n(TIM 5)\nA=(IMG)\n(MOV 0,0)\n(END)\n"


def checked(tmp_path: Path, text: str) -> str:
    (tmp_path / "p.rob").write_text(text)
    return rl1c("check", tmp_path / "p.rob", "--color", "never").stdout


def test_a_jump_target_of_three_digits_is_told_the_range_of_jump_targets(
    tmp_path: Path,
) -> None:
    out = checked(tmp_path, ":100 (MOV 0,0)\n#100\n(END)\n")
    assert "help: labels run from `:00` to `:99`" in out
    assert "help: jump targets run from `#00` to `#99`" in out
    assert "labels run from `#" not in out  # a label is never written with `#`


def test_an_argument_to_a_call_that_takes_none_is_told_how_to_write_the_call(
    tmp_path: Path,
) -> None:
    out = checked(tmp_path, "(MOV 0,0)\n(FRE 1)\n(CAM Z 4)\n(END)\n")
    assert "`(FRE)` takes no arguments, found 1" in out
    assert "help: write `(FRE)`" in out
    assert "help: write `(CAM Z)`" in out


def run_ilc(path: Path) -> str:
    result = rl1c("run", path, "--color", "never")
    assert result.exit_code == 1, result.output
    return result.stderr


def test_rl1c_run_names_a_file_that_is_no_ilc_file_as_rl1c_dis_does(tmp_path: Path) -> None:
    other = tmp_path / "photo.ilc"
    other.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(40))
    out = run_ilc(other)
    assert "is not valid: it does not start with `RLIC` (its first bytes are 89 50 4E 47)" \
           in out
    assert "b'" not in out  # no Python bytes repr
    assert "help: check that this is the .ilc file you meant" in out
    assert out == rl1c("dis", other).stderr


def test_source_named_ilc_is_told_a_compile_command_that_works(tmp_path: Path) -> None:
    misnamed = tmp_path / "p.ilc"
    misnamed.write_text(PROGRAM)
    out = run_ilc(misnamed)
    assert "is not valid: it is text, not compiled code" in out
    source, compiled = tmp_path / "p.rob", tmp_path / "p.ilc"
    assert f"`rl1c compile {source} -o {compiled}`, then give {compiled}" in out
    # The advice, followed, works (compiling p.ilc onto itself is refused).
    misnamed.rename(source)
    assert rl1c("compile", source, "-o", compiled).exit_code == 0
    assert rl1c("run", compiled).exit_code == 13  # (IMG) without a script: it ran


def test_a_damaged_ilc_file_says_what_to_do_once(tmp_path: Path) -> None:
    (tmp_path / "p.rob").write_text(PROGRAM)
    compiled = tmp_path / "p.ilc"
    assert rl1c("compile", tmp_path / "p.rob", "-o", compiled).exit_code == 0
    data = bytearray(compiled.read_bytes())
    data[-1] ^= 0xFF
    compiled.write_bytes(data)
    out = run_ilc(compiled)
    assert "byte 8: CRC-32 mismatch: the header says 0x" in out
    assert out.count("compile") == 1 and "help: compile the program again" in out


def test_the_container_reader_shows_a_wrong_start_in_hex() -> None:
    try:
        ilc.decode(b"\x00\x01ab" + bytes(40))
    except ilc.IlcFormatError as error:
        assert error.message == ("not an .ilc file: it does not start with `RLIC` (its "
                                 "first bytes are 00 01 61 62)")
    else:
        raise AssertionError("decoded a file that does not start with RLIC")


def script_says(tmp_path: Path, name: str, text: str) -> str:
    (tmp_path / "p.rob").write_text(PROGRAM)
    (tmp_path / name).write_text(text)
    result = rl1c("run", tmp_path / "p.rob", "--sensors", tmp_path / name, "--color", "never")
    assert result.exit_code == 2, result.output
    return result.stderr.splitlines()[0]


def test_a_misspelt_key_of_a_sensor_script_is_told_the_key_it_is_close_to(
    tmp_path: Path,
) -> None:
    assert ': IMGG: unknown key; did you mean "IMG"? (expected one of "IMG", "KYO", ' \
           in script_says(tmp_path, "s.json", '{"IMGG": [{"area": 1}]}')
    assert script_says(tmp_path, "s.json", '{"line_lost": [{"durin": "MOV"}]}').endswith(
        ': line_lost[0].durin: unknown key; did you mean "during"? (expected one of "time", '
        '"instruction", "during", "nth", "after")')
    assert "did you mean" not in script_says(tmp_path, "s.json", '{"zzzz": 1}')
    # A form is a key of `fail`: written as each format writes that key.
    assert ': fail.tim: not a built-in form; did you mean "TIM"? (expected one of "CAM A", ' \
           in script_says(tmp_path, "s.json", '{"fail": {"tim": 1}}')
    assert ': fail.tim: not a built-in form; did you mean TIM? (expected one of "CAM A", ' \
           in script_says(tmp_path, "s.toml", '[fail]\ntim = 1\n')
    # As near to CAM A as to CAM Z: no guess.
    assert "did you mean" not in script_says(tmp_path, "s.json", '{"fail": {"CAM X": 1}}')


def test_toml_keys_are_quoted_as_toml_needs_them(tmp_path: Path) -> None:
    says = script_says(tmp_path, "s.toml", "ult_a = [1]\n")
    assert ': ult_a: unknown key; did you mean "ULT A"? (expected one of IMG, KYO, "CAM R", ' \
           '"ULT A",' in says


def test_a_json_script_missing_a_key_is_told_what_to_write(tmp_path: Path) -> None:
    says = script_says(tmp_path, "s.json", '{"IMG": [{"area": 1, "x": 2}]}')
    assert says.endswith('is not valid: IMG[0]: missing "y", "z"; write "y": ...')


WORLD = """[floor]
size = [600, 400]

[start]
x = 60
y = 200

[[stands]]
name = "bench"
x = 400
y = 330
facng = -135
"""


def test_a_misspelt_key_of_a_world_file_and_of_a_sweep_are_told_the_close_key(
    tmp_path: Path,
) -> None:
    (tmp_path / "p.rob").write_text(PROGRAM)
    (tmp_path / "w.toml").write_text(WORLD)
    says = rl1c("sim", tmp_path / "p.rob", "--world", tmp_path / "w.toml").stderr
    assert "the world file is not valid: stands[0].facng: unknown key; did you mean facing? " \
           "(expected one of name, x, y, width, depth, facing, height, marker_height)\n" \
           f"  --> {tmp_path / 'w.toml'}:12\n" in says  # the gutter as wide as 12
    (tmp_path / "w.toml").write_text(WORLD.replace("facng", "facing"))
    swept = rl1c("sim", tmp_path / "p.rob", "--world", tmp_path / "w.toml", "--runs", "2",
                 "--sweep", "stands.bench.facng=0:40:3")
    assert swept.exit_code == 2
    assert "--sweep: stands.bench.facng: unknown key; did you mean facing? (expected one of " \
           "x, y, facing)" in swept.stderr


KEYS = ["IMG", "KYO", "CAM R", "ULT A", "line_lost", "after_last", "comment"]


@given(st.text(max_size=60))
def test_a_guess_is_always_one_of_the_keys_and_a_known_key_guesses_itself(key: str) -> None:
    listed = ", ".join(map(json.dumps, KEYS))
    said = unknown_key(key, KEYS, json.dumps)
    guess = said.removeprefix("unknown key; did you mean ").removesuffix(
        f"? (expected one of {listed})")
    assert said == f"unknown key; expected one of {listed}" or guess in map(json.dumps, KEYS)
    for known in KEYS:
        assert unknown_key(known.lower(), KEYS, str).startswith(
            f"unknown key; did you mean {known}? (expected one of IMG, ")


def test_a_missing_handler_fault_names_the_label_to_add_as_the_checker_does(
    tmp_path: Path,
) -> None:
    (tmp_path / "p.rob").write_text("(TRC 3)\n(MVI 1,1,50)\n(MOV 0,0)\n(END)\n")
    (tmp_path / "s.json").write_text('{"line_lost": [{"during": "MVI", "nth": 1}]}')
    for engine in ("vm", "ast"):
        result = rl1c("run", tmp_path / "p.rob", "--sensors", tmp_path / "s.json",
                      "--engine", engine, "--color", "never")
        assert result.exit_code == 11
        assert "error[E1011]: the line was lost during MVI in tracing mode 3, which jumps " \
               "to :97, but the program has no label :97" in result.stdout
        assert "help: add the handler label: a line that starts with `:97` and says what " \
               "the vehicle does when it loses the line, e.g. `:97 (MOV 0,0); (END)`" \
               in result.stdout


def test_a_stray_equals_sign_is_told_how_an_assignment_is_written(tmp_path: Path) -> None:
    out = checked(tmp_path, "=3\nA==3\n?A<10\n(END)\n")
    assert "expected `(`, `;`, `?`, a jump target `#NN`, a label, a variable or the end of " \
           "the line, found `=`\n" in out
    assert "help: an assignment starts with the variable it sets, as in `A=3`" in out
    assert "help: `=` is written once, as in `A=3`; a comparison is a jump, as in `?A=#10`" \
           in out
    # Only where a jump target is what the line needs is the help about one.
    assert out.count("help: a jump target is `#` and two digits, e.g. `#10`") == 1


def test_an_unexpected_character_that_cannot_be_seen_is_named_by_its_code_point(
    tmp_path: Path,
) -> None:
    (tmp_path / "p.rob").write_bytes(
        "A=1\u00a0\nB=\u200b2\nC=\x01\nD=\ue000\nE=\u00e9\n(END)\n".encode())
    out = rl1c("check", tmp_path / "p.rob", "--format", "concise").stdout
    assert [line.partition(" error[E0102]: ")[2] for line in out.splitlines()[:-1]] == [
        "unexpected character U+00A0 (NO-BREAK SPACE)",
        "unexpected character U+200B (ZERO WIDTH SPACE)",
        "unexpected character U+0001",
        "unexpected character U+E000",  # private use: no name, nothing a terminal shows
        "unexpected character `\u00e9` (LATIN SMALL LETTER E WITH ACUTE)",
    ]


def test_a_scene_s_window_turned_round_is_shown_with_how_to_write_one(tmp_path: Path) -> None:
    (tmp_path / "p.rob").write_text(PROGRAM)
    world = WORLD.replace("facng", "facing") + (
        '\n[[scenes]]\nnumber = 2\nsees = ["markers"]\nwindow = [100, 0, 50, 240]\n')
    (tmp_path / "w.toml").write_text(world)
    result = rl1c("sim", tmp_path / "p.rob", "--world", tmp_path / "w.toml")
    assert result.exit_code == 2
    assert "is not valid: scenes[0].window: [100, 0, 50, 240] is no window: " \
           "write [x0, y0, x1, y1], its left, top, right and bottom edges in pixels, with " \
           f"x0 < x1 and y0 < y1\n  --> {tmp_path / 'w.toml'}:17\n" in result.stderr


def test_readings_used_up_are_told_what_to_write_in_the_script_s_own_syntax(
    tmp_path: Path,
) -> None:
    (tmp_path / "p.rob").write_text(":10 A=(IMG)\n#10\n")
    (tmp_path / "s.toml").write_text("IMG = [{ area = 1, x = 1, y = 1, z = 1 }]\n")
    result = rl1c("run", tmp_path / "p.rob", "--sensors", tmp_path / "s.toml",
                  "--color", "never")
    assert result.exit_code == 13
    assert "error[E1013]: (IMG) at 100 ms has no reading: it is call 2, and the sensor script " \
           f"{tmp_path / 's.toml'} gives 1 IMG reading" in result.stdout
    assert 'help: add readings to the sensor script (spec/sensors.md), or set its after_last ' \
           'to "repeat" to repeat the last one' in result.stdout
    assert '"after_last":' not in result.stdout  # JSON's syntax, in a TOML script's help
