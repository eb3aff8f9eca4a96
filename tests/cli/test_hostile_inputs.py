"""Every command on hostile input: arbitrary bytes, generated and mutated programs
through check, fmt, compile and both engines; mutated .ilc files (the CRC mostly fixed)
through run, dis and asm; arbitrary, mutated and hostile-valued world files through sim.
Nothing may end in an internal error, an undocumented exit
status or an output written by a command that failed (tests/support/hostile.py;
bench/hostile_fuzz.py runs the same attacks for as long as asked)."""

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from support.hostile import (
    hostile_ilc_files,
    hostile_sources,
    hostile_worlds,
    ilc_attack,
    source_attack,
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
