"""Test files of `rl1c test` (compiler/test_file.py, spec/tests.md): what the schema
accepts, and every mistake refused as `file:line: key: what; what to write`."""

from __future__ import annotations

import json
from typing import get_args

import msgspec
import pytest
from hypothesis import given
from hypothesis import strategies as st
from support import EXAMPLES, ROOT

from rl1.compiler.test_file import (
    Ends,
    Expect,
    Success,
    is_test_file,
    load_test_file,
    parse_call,
)
from rl1.compiler.test_file import Test as Table  # pytest would collect a class Test*
from rl1.vm.config import ConfigError
from rl1.vm.faults import FaultKind
from rl1.vm.sensor_script import FORMS

NAME = "t.tests.toml"


def load(text: str) -> list[object]:
    return list(load_test_file(text.encode(), NAME).test)


def refusal(text: str) -> ConfigError:
    with pytest.raises(ConfigError) as caught:
        load(text)
    return caught.value


MINIMAL = '[[test]]\nname = "it ends"\nprogram = "main.rob"\n'


def test_a_minimal_test_expects_the_run_to_end_normally() -> None:
    (test,) = load_test_file(MINIMAL.encode(), NAME).test
    assert (test.name, test.program, test.seed, test.engine) == ("it ends", "main.rob", 0, "vm")
    assert test.expect.ends == "normally"
    assert test.expect.variables == {} and test.expect.calls == []


def test_every_expectation_is_read() -> None:
    (test,) = load_test_file(b"""
[[test]]
name = "all"
program = "p.ilc"
world = "w.toml"
seed = 7
budget = 500
expect.ends = "device-error"
expect.goal = "missed"
expect.variables = { C = 14, "@" = -3 }
expect.calls = ["MOV 3,3", "CAM P", "IMG"]
""", NAME).test
    expect = test.expect
    assert (test.world, test.seed, test.budget) == ("w.toml", 7, 500)
    assert (expect.ends, expect.goal) == ("device-error", "missed")
    assert expect.variables == {"C": 14, "@": -3}
    assert expect.calls == ["MOV 3,3", "CAM P", "IMG"]


def test_a_success_rate_is_read() -> None:
    (test,) = load_test_file(b'[[test]]\nname = "r"\nprogram = "p.rob"\nworld = "w.toml"\n'
                             b"expect.success = { runs = 20, at_least = 0.9 }\n", NAME).test
    assert test.expect.success == Success(runs=20, at_least=0.9)


def test_the_endings_are_normally_and_the_fault_kinds_of_a_run() -> None:
    # The schema's Literal is written out for editors' JSON Schema; held to faults.py here.
    kinds = {kind.code for kind in FaultKind} - {FaultKind.ABORTED.code}  # no firmware here
    assert set(get_args(Ends)) == {"normally", *kinds}


@pytest.mark.parametrize(("text", "line", "where", "detail"), [
    (MINIMAL + 'expect.ends = "crashed"\n', 4, "test[0].expect.ends",
     'or "missing-handler" or "normally", found the string "crashed"'),
    (MINIMAL + "expect.variables = { CC = 1 }\n", 4, "test[0].expect.variables.CC",
     "expected a variable's name, A-Z, a-z or @"),
    (MINIMAL + "expect.variables = { C = 40000 }\n", 4, "test[0].expect.variables.C",
     "40000 is outside -32768..32767"),
    (MINIMAL + 'expect.calls = ["MOV 3,3", "MOVE 3"]\n', 4, "test[0].expect.calls[1]",
     '"MOVE 3" is no call; write one as the trace shows it'),
    (MINIMAL + "expect.goal = \"met\"\n", 4, "test[0].expect.goal",
     "a goal is judged on a world"),
    (MINIMAL + 'world = "w.toml"\nsensors = "s.toml"\n', 5, "test[0].sensors",
     "not both"),
    (MINIMAL + 'world = "w.toml"\nexpect.success = { runs = 0, at_least = 0.5 }\n', 5,
     "test[0].expect.success.runs", "0 is outside 1..100000"),
    (MINIMAL + 'world = "w.toml"\nexpect.success = { runs = 5, at_least = 1.5 }\n', 5,
     "test[0].expect.success.at_least", "1.5 is outside 0..1"),
    (MINIMAL + 'world = "w.toml"\nexpect.variables = { A = 1 }\n'
     "expect.success = { runs = 5, at_least = 0.5 }\n", 5, "test[0].expect.variables",
     "a success rate judges many runs"),
    (MINIMAL + 'world = "w.toml"\nseed = 4294967295\n'
     "expect.success = { runs = 5, at_least = 0.5 }\n", 6, "test[0].expect.success.runs",
     "the seeds 4294967295..4294967299 leave 0..4294967295"),
    (MINIMAL + 'engine = "ast"\n', None, "", ""),  # accepted: .rob source
    ('[[test]]\nname = "x"\nprogram = "p.ilc"\nengine = "ast"\n', 4, "test[0].engine",
     "not an .ilc file"),
    (MINIMAL + MINIMAL, 5, "test[1].name", 'a second test named "it ends"'),
    ('[[test]]\nname = "x"\n', 1, "test[0]", "missing `program`"),
    (MINIMAL + "colour = 3\n", 4, "test[0].colour", "unknown key; expected one of name"),
    ("test = []\n", 1, "test", "expected at least one [[test]] table"),
    ("", None, "", "no [[test]] table; add one"),
    ("[floor]\nsize = [1, 1]\n", None, "", "this looks like a world file"),
    ('"ULT A" = [1]\n', None, "", "this looks like a sensor script"),
    ("[[test]\n", 1, "", "invalid TOML"),
])
def test_mistakes_are_refused_with_their_line_and_what_to_write(
        text: str, line: int | None, where: str, detail: str) -> None:
    if not detail:
        load(text)
        return
    error = refusal(text)
    assert (error.file, error.line, error.where) == (NAME, line, where)
    assert detail in error.detail


def test_a_huge_number_is_refused_without_reading_it_whole() -> None:
    error = refusal(MINIMAL + "seed = " + "9" * 5000 + "\n")
    assert error.line == 4 and "more than 4300 digits" in error.detail


def test_the_examples_test_file_is_valid() -> None:
    files = sorted(EXAMPLES.glob("*.tests.toml"))
    assert files
    for file in files:
        assert load_test_file(file.read_bytes(), str(file)).test


@pytest.mark.parametrize(("name", "expected"), [
    ("main.tests.toml", True), ("dir/rl1.tests.toml", True), ("X.TESTS.TOML", True),
    ("main.toml", False), ("tests.toml", False), ("main.tests.toml.bak", False)])
def test_test_files_are_known_by_their_name(name: str, expected: bool) -> None:
    assert is_test_file(name) is expected


@given(st.sampled_from(sorted(FORMS)),
       st.none() | st.lists(st.integers(-32768, 32767), min_size=1, max_size=4))
def test_a_call_as_the_trace_shows_it_is_read_back(form: str, args: list[int] | None) -> None:
    text = form if args is None else f"{form} {','.join(map(str, args))}"
    assert parse_call(text) == (form, None if args is None else tuple(args))


@given(st.text(max_size=20))
def test_any_text_is_a_call_or_none_never_an_exception(text: str) -> None:
    found = parse_call(text)
    assert found is None or found[0] in FORMS


def test_the_json_schema_names_every_key_the_loader_accepts() -> None:
    document = json.loads((ROOT / "spec" / "schemas" / "tests.schema.json").read_text())
    for struct in (Table, Expect, Success):
        table = document["$defs"][struct.__name__]
        assert set(table["properties"]) == {f.encode_name for f in msgspec.structs.fields(struct)}
        assert table["additionalProperties"] is False


@given(st.binary(max_size=200) | st.text(max_size=200).map(str.encode))
def test_any_bytes_are_a_test_file_or_a_config_error(data: bytes) -> None:
    try:
        load_test_file(data, NAME)
    except ConfigError as error:
        assert error.file == NAME and error.detail


def toml_value(value: object) -> str:
    """`value` written as TOML: JSON's strings, integers, booleans and arrays are TOML's."""
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{json.dumps(key)} = {toml_value(item)}"
                                for key, item in value.items()) + " }"
    return json.dumps(value)


VALUES = (st.booleans() | st.integers() | st.text(max_size=8)
          | st.lists(st.integers() | st.text(max_size=4), max_size=3))


@given(st.dictionaries(
    st.sampled_from(["name", "program", "world", "sensors", "seed", "engine", "budget",
                     "expect"]),
    VALUES | st.dictionaries(st.sampled_from(["ends", "goal", "variables", "calls",
                                              "success", "A"]),
                             VALUES | st.dictionaries(st.sampled_from(
                                 ["A", "runs", "at_least", "@", "AB"]), VALUES, max_size=3),
                             max_size=4),
    max_size=8))
def test_any_table_of_the_keys_is_a_test_or_a_config_error_at_a_line(
        table: dict[str, object]) -> None:
    text = "[[test]]\n" + "".join(f"{key} = {toml_value(value)}\n"
                                  for key, value in table.items())
    try:
        load(text)
    except ConfigError as error:
        assert error.detail
        assert error.line is None or 1 <= error.line <= len(table) + 1
