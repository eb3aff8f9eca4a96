"""A test file of `rl1c test` (spec/tests.md): its schema, and loading and validating it.

A test file is TOML, named `*.tests.toml` (TEST_FILE_SUFFIX), a list of `[[test]]`
tables, each naming a program, where it runs (a world, a sensor script, or neither)
and what must hold:

    [[test]]
    name = "Listing 1 meets its goal on the scene of Fig. 4"
    program = "sample.rob"              # from this file's folder; .rob or .ilc
    world = "sample.world.toml"         # or sensors = "sample.sensors.toml"
    expect.goal = "met"
    expect.variables = { C = 579 }
    expect.calls = ["STR 75", "FRE"]

The schema is `TestFile` (msgspec, through rl1.vm.config, the configuration files' one
validation layer, which also gives editors spec/schemas/tests.schema.json); the checks
that span keys are here. Every failure is a ConfigError `file:line: key: what; what to
write`. This module loads msgspec and the language facts only, so that the language
server checks a test file without loading the back end.
"""

from __future__ import annotations

import os
import re
from typing import Annotated, Literal

import msgspec
from msgspec import UNSET, Meta, Struct, UnsetType

from rl1.vm.config import (
    SENSOR_SCRIPT,
    WORLD,
    ConfigError,
    FileKind,
    Int16,
    convert,
    error_at,
    read_document,
)
from rl1.vm.defaults import DEFAULT_BUDGET, Engine
from rl1.vm.faults import MAX_BUDGET
from rl1.vm.language import VARIABLES
from rl1.vm.sensor_script import FORMS

TEST_FILE_SUFFIX = ".tests.toml"
"""How `rl1c test` finds test files in a folder, and the language server knows one."""

MAX_SEED = 2**32 - 1  # `rl1c sim --seed`'s range
MAX_RUNS = 100_000  # of a success rate: a campaign of `rl1c sim --runs` is for more

TEST_FILE = FileKind("a test file", "rl1c test", "spec/tests.md", ("test",))

Ends = Literal["normally", "argument-range", "missing-handler", "budget", "device-error"]
"""How a run is to end: normally, or with the fault of that kind (its code in `rl1c run
--format json`; tests/cli/test_test_file.py holds them to vm/faults.py's)."""

VariableName = Annotated[str, Meta(pattern=f"^[{VARIABLES}]$", extra={
    "expected": "a variable's name, A-Z, a-z or @"})]
CallText = Annotated[str, Meta(min_length=1, max_length=80, extra={
    "expected": 'a call as the trace shows it, such as "MOV 3,3" or "IMG"'})]
Path = Annotated[str, Meta(min_length=1, max_length=4096, description=(
    "a path from the test file's folder"))]


CONTROL = re.compile("[\x00-\x1f\x7f-\x9f]")
"""A control character (C0, DEL, C1): none in a path; shown as U+FFFD in a name."""


def is_test_file(name: str) -> bool:
    """Whether the file `name` is a test file, by its name (in any case)."""
    return os.path.basename(name).lower().endswith(TEST_FILE_SUFFIX)


CallPattern = tuple[str, tuple[int, ...] | None]
"""A call of `expect.calls`: its form (`MOV`, `CAM P`) and arguments (None: any)."""


def parse_call(text: str) -> CallPattern | None:
    """`MOV 3,3` as ("MOV", (3, 3)), `IMG` as ("IMG", None); None when `text` is no
    call as the trace shows one."""
    words = text.split(" ")
    for length in (2, 1):
        form = " ".join(words[:length])
        if len(words) >= length and form in FORMS and len(words) <= length + 1:
            if len(words) == length:
                return form, None
            try:
                return form, tuple(int(arg) for arg in words[length].split(","))
            except ValueError:
                return None
    return None


class Success(Struct, forbid_unknown_fields=True, kw_only=True):
    """A success rate over seeded runs on the simulator: `runs` runs from the test's
    seed, of which at least the fraction `at_least` end normally and meet the world's
    goal (when it has one)."""

    runs: Annotated[int, Meta(ge=1, le=MAX_RUNS, description="the runs, seeds seed, "
                                                              "seed + 1, ...")]
    at_least: Annotated[float, Meta(ge=0, le=1, description=(
        "the least fraction of the runs that succeed, 0..1 (0.9 is 90 %)"))]


class Expect(Struct, forbid_unknown_fields=True, kw_only=True):
    """What must hold of the run (or, with `success`, of the runs)."""

    ends: Annotated[Ends, Meta(description=(
        "normally (the default), or the kind of fault the run ends with"))] = "normally"
    goal: Annotated[Literal["met", "missed"], Meta(description=(
        "the world's [goal] is met or missed"))] | UnsetType = UNSET
    variables: Annotated[dict[VariableName, Int16], Meta(
        description="final values of variables, such as { C = 14 }", extra={
            "expected": "a table of variables' final values, such as { C = 14 }"})] = {}
    calls: Annotated[list[CallText], Meta(description=(
        "calls the trace holds, each somewhere in it: `MOV 3,3` with these arguments, "
        "`IMG` with any"))] = []
    success: Success | UnsetType = UNSET


class Test(Struct, forbid_unknown_fields=True, kw_only=True):
    """One test: a program, where it runs, and what must hold."""

    name: Annotated[str, Meta(min_length=1, max_length=200,
                              description="unique in the file; shown in the report")]
    program: Annotated[Path, Meta(description="the program: .rob source, compiled in "
                                              "memory, or an .ilc file")]
    world: Annotated[Path, Meta(description="a world file: the run is `rl1c sim`'s")
                     ] | UnsetType = UNSET
    sensors: Annotated[Path, Meta(description="a sensor script: the run is `rl1c run`'s")
                       ] | UnsetType = UNSET
    seed: Annotated[int, Meta(ge=0, le=MAX_SEED, description="the seed of the world's "
                                                              "noise (the first seed of "
                                                              "a success rate)")] = 0
    engine: Engine = "vm"
    budget: Annotated[int, Meta(ge=1, le=MAX_BUDGET)] = DEFAULT_BUDGET
    expect: Expect = msgspec.field(default_factory=Expect)


class TestFile(Struct, forbid_unknown_fields=True):
    """A test file of `rl1c test` (spec/tests.md), named *.tests.toml."""

    test: Annotated[list[Test], Meta(min_length=1, extra={
        "expected": "at least one [[test]] table"})]


def load_test_file(data: bytes, name: str) -> TestFile:
    """The test file `name` from its bytes; ConfigError says what is wrong and where."""
    document, text = read_document(data, name, "toml")
    for other in (WORLD, SENSOR_SCRIPT):
        TEST_FILE.refuse_other(document, name, other)
    if "test" not in document:
        raise ConfigError(name, None, "", "no [[test]] table; add one, such as [[test]] "
                          'name = "it ends" program = "main.rob" (spec/tests.md)')
    tests = convert(document, TestFile, name, text)
    _check(tests, name, text)
    return tests


def _check(tests: TestFile, name: str, text: str) -> None:
    """The checks that span keys."""
    seen: set[str] = set()
    for index, test in enumerate(tests.test):
        def fail(*path: str | int, detail: str, index: int = index) -> ConfigError:
            return error_at(name, text, ("test", index, *path), detail)

        if test.name in seen:
            raise fail("name", detail=f'a second test named "{test.name}"; give each '
                                      "test a name of its own")
        seen.add(test.name)
        # The report prints paths: a control character would reach the terminal (an
        # escape sequence), and NUL no file's name holds.
        for key, value in (("program", test.program), ("world", test.world),
                           ("sensors", test.sensors)):
            if isinstance(value, str) and (found := CONTROL.search(value)):
                raise fail(key, detail=f"holds the control character U+{ord(found[0]):04X}; "
                                       "write it without one")
        has_world = not isinstance(test.world, UnsetType)
        if has_world and not isinstance(test.sensors, UnsetType):
            raise fail("sensors", detail="a test runs on a world or on a sensor script, "
                                         "not both; write two tests")
        if test.engine == "ast" and test.program.lower().endswith(".ilc"):
            raise fail("engine", detail='"ast" interprets RL/I source, not an .ilc file; '
                                        'name the .rob file, or leave out engine')
        expect = test.expect
        if not has_world:
            for key, given in (("goal", expect.goal), ("success", expect.success)):
                if not isinstance(given, UnsetType):
                    raise fail("expect", key, detail="a goal is judged on a world: give "
                                                     "the test world = \"FILE\"")
        for number, call in enumerate(expect.calls):
            if parse_call(call) is None:
                raise fail("expect", "calls", number, detail=(
                    f'"{call}" is no call; write one as the trace shows it, such as '
                    '"MOV 3,3", "CAM P 400" or "IMG"'))
        if isinstance(expect.success, Success):
            others = [key for key, given in (("ends", expect.ends != "normally"),
                                             ("goal", not isinstance(expect.goal, UnsetType)),
                                             ("variables", bool(expect.variables)),
                                             ("calls", bool(expect.calls))) if given]
            if others:
                raise fail("expect", others[0], detail=(
                    "a success rate judges many runs, and this expects one run's; "
                    "write it in a test of its own"))
            if test.seed + expect.success.runs - 1 > MAX_SEED:
                raise fail("expect", "success", "runs", detail=(
                    f"the seeds {test.seed}..{test.seed + expect.success.runs - 1} leave "
                    f"0..{MAX_SEED}; give fewer runs or a smaller seed"))
