"""Every command on hostile input: arbitrary bytes, generated and mutated programs
through check, fmt, compile and both engines; mutated .ilc files (the CRC mostly fixed)
through run, dis and asm; arbitrary, mutated and hostile-valued world files through sim;
test files (mutated, of hostile values, naming a FIFO, a link loop, /dev/zero) through
rl1c test; worlds with hostile [vary] tables and hostile --sweep arguments through a
campaign with pictures and a seeded run; rl1c new into every kind of place; --junit and
a campaign's pictures onto inputs, folders, links and read-only files.
Nothing may end in an internal error, an undocumented exit
status or an output written by a command that failed (tests/support/hostile.py;
bench/hostile_fuzz.py runs the same attacks for as long as asked)."""

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from support.hostile import (
    NEW_TARGETS,
    OUTPUT_TARGETS,
    attack_with_test_file,
    hostile_ilc_files,
    hostile_sources,
    hostile_sweeps,
    hostile_test_files,
    hostile_vary_worlds,
    hostile_worlds,
    ilc_attack,
    new_attack,
    output_attack,
    source_attack,
    vary_attack,
    world_attack,
)

FUZZ = settings(max_examples=300, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])


@FUZZ
@given(data=hostile_sources())
def test_source_commands_survive_hostile_sources(data: bytes, tmp_path: Path) -> None:
    assert source_attack(data, tmp_path) == []


@FUZZ
@given(data=hostile_ilc_files())
def test_ilc_commands_survive_mutated_files(data: bytes, tmp_path: Path) -> None:
    assert ilc_attack(data, tmp_path) == []


@pytest.mark.parametrize("data", [b"", b"\x00", b"\xff\xfe", b"A=" + b"9" * 5000, b"\r\r\n"])
def test_source_commands_survive_known_hard_inputs(data: bytes, tmp_path: Path) -> None:
    assert source_attack(data, tmp_path) == []


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=hostile_worlds())
def test_sim_survives_hostile_world_files(data: bytes, tmp_path: Path) -> None:
    assert world_attack(data, tmp_path) == []


def test_sim_survives_a_line_as_wide_as_a_world_allows(tmp_path: Path) -> None:
    """A line 1e6 cm wide once made every tracing tick look through 10^9 cells."""
    world = (Path(__file__).parents[2] / "examples" / "sample.world.toml").read_bytes()
    assert b"width = 2\n" in world
    assert world_attack(world.replace(b"width = 2\n", b"width = 1e6\n", 1), tmp_path) == []


@pytest.mark.parametrize("value", [b"nan", b"inf", b"1e308", b"[[0, 0], [1e6, 1e6]]",
                                   b"[" * 600 + b"]" * 600, b"9" * 5000])
def test_sim_survives_known_hard_world_values(value: bytes, tmp_path: Path) -> None:
    world = (Path(__file__).parents[2] / "examples" / "sample.world.toml").read_bytes()
    assert world_attack(world.replace(b"[800, 500]", value), tmp_path) == []


@settings(max_examples=100, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=hostile_test_files())
def test_rl1c_test_survives_hostile_test_files(data: bytes, tmp_path: Path) -> None:
    assert attack_with_test_file(data, tmp_path) == []


@pytest.mark.parametrize("path", ["fifo.rob", "loop.rob", "zero.rob", "folder.rob",
                                  "a\\u0000b.rob", "hostile.ilc"])
def test_rl1c_test_survives_a_test_file_naming_a_hostile_file(path: str,
                                                               tmp_path: Path) -> None:
    data = f'[[test]]\nname = "x"\nprogram = "{path}"\n'.encode()
    assert attack_with_test_file(data, tmp_path) == []


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(world=hostile_vary_worlds(), sweeps=hostile_sweeps())
def test_sim_survives_hostile_vary_tables_and_sweeps(world: bytes, sweeps: tuple[str, ...],
                                                     tmp_path: Path) -> None:
    assert vary_attack(world, sweeps, tmp_path) == []


@pytest.mark.parametrize("kind", NEW_TARGETS)
def test_rl1c_new_into_any_place_makes_a_whole_project_or_nothing(
        kind: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert new_attack(kind, tmp_path) == []


@pytest.mark.parametrize(("command", "kind"), [
    (command, kind) for command in ("test", "svg", "html") for kind in OUTPUT_TARGETS
    if kind != "test file" or command == "test"])  # the test file is rl1c test's input
def test_outputs_onto_hostile_targets_change_no_input(
        command: str, kind: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert output_attack(command, kind, tmp_path) == []
