"""Every command on hostile input: arbitrary bytes, generated and mutated programs
through check, fmt, compile and both engines; mutated .ilc files (the CRC mostly fixed)
through run, dis and asm. Nothing may end in an internal error, an undocumented exit
status or an output written by a command that failed (tests/support/hostile.py;
bench/hostile_fuzz.py runs the same attacks for as long as asked)."""

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from support.hostile import hostile_ilc_files, hostile_sources, ilc_attack, source_attack

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
