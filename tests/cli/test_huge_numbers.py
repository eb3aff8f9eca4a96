"""Numbers of any length (Python refuses to convert a decimal of more than 4,300 digits)
get the out-of-range message a number like 99999 gets, everywhere a number is read: RL/I
constants and labels, the .ils text and sensor scripts."""

import json
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st
from support.cli import rl1c

from rl1.vm.language import TOO_LONG, decimal_value

LONG = "1" * 5000


def check_json(source: str) -> tuple[int, list[tuple[str, int, int]]]:
    result = rl1c("check", "--format", "json", "-", stdin=source.encode())
    found = json.loads(result.stdout)
    return result.exit_code, [(d["code"], d["line"], d["column"]) for d in found]


@given(digits=st.integers(6, 12_000), sign=st.sampled_from(["", "-"]))
@settings(max_examples=30, deadline=None)
def test_a_decimal_constant_of_any_length_is_out_of_range_like_99999(digits: int,
                                                                     sign: str) -> None:
    assert check_json(f"A={sign}{'9' * digits}\n(END)\n") == check_json(f"A={sign}99999\n(END)\n")


def test_a_huge_call_argument_is_out_of_range() -> None:
    status, found = check_json(f"(MOV {LONG},0)\n(END)\n")
    assert status == 1 and [code for code, *_ in found] == ["E0507"]


def test_labels_and_jump_targets_of_thousands_of_digits_are_malformed_labels() -> None:
    status, found = check_json(f":{LONG} A=1\n#{LONG}\n(END)\n")
    assert status == 1
    assert [code for code, *_ in found if code.startswith("E")] == ["E0201", "E0202"]


def test_a_label_of_leading_zeros_still_gets_its_two_digit_fix() -> None:
    result = rl1c("check", "-", stdin=b":007 A=1\n(END)\n")
    assert result.exit_code == 1 and "write `:07`" in result.stdout


@given(text=st.from_regex(r"\A[-+]?[0-9]{1,40}\Z"))
def test_decimal_value_is_exact_wherever_a_value_can_fit(text: str) -> None:
    value = decimal_value(text)
    if len(text.lstrip("+-").lstrip("0")) <= 18:
        assert value == int(text)
    else:
        assert abs(value) == TOO_LONG and (value < 0) == text.startswith("-")


def test_asm_refuses_a_huge_immediate_and_handler_offset(tmp_path: Path) -> None:
    for directive in (f"LDI {LONG}", f".handler 96 {LONG}"):
        source = tmp_path / "huge.ils"
        source.write_text(f".version 1 0\n{directive}\nEND\n", encoding="utf-8")
        result = rl1c("asm", source, "-o", tmp_path / "huge.ilc")
        assert result.exit_code == 1, result.output
        assert "out of range" in result.stderr and "internal error" not in result.output
        assert not (tmp_path / "huge.ilc").exists()


def test_sensor_scripts_with_huge_readings_or_ports_are_script_errors(tmp_path: Path) -> None:
    program = tmp_path / "p.rob"
    program.write_text("A=(INP 3)\n(END)\n", encoding="utf-8")
    scripts = {
        "reading.json": f'{{"ULT A": [{LONG}]}}',
        "port.json": f'{{"INP": {{"{LONG}": [1]}}}}',
        "reading.toml": f'"ULT A" = [{LONG}]\n',
    }
    for name, text in scripts.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
        result = rl1c("run", program, "--sensors", tmp_path / name)
        assert result.exit_code == 2, result.output
        assert result.stderr.startswith("error[E0100]: the sensor script is not valid: ")
        assert "internal error" not in result.output
