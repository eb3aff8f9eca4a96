"""`rl1c reduce --engine` when an engine ends the process it runs in (the C VM crashing
in rl1c's process through ctypes, an abort, the memory exhausted): a difference kept
while reducing, as a disagreement is, with rl1c outliving each one. rl1c runs in a
process of its own (tests/support/ending_rl1c.py), so that a failure is a status here,
not pytest ended."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from support import ROOT
from support.planted import crashing_c_vm

from rl1.compiler.cli.reduce import _may_end_its_process
from rl1.compiler.differential import engine_named

pytestmark = pytest.mark.slow  # a process of rl1c for each test, forking one a case

ENDING_RL1C = str(ROOT / "tests" / "support" / "ending_rl1c.py")
CRASHING = "A=1234"  # the line on which the engine ends its process
KILLER = f"ends-on:{CRASHING}"
PROGRAM = f"B=1\n{CRASHING}\nC=2\nD=B+C ' the sum\n"


def ending_rl1c(*args: str | Path, env: dict[str, str] | None = None
                ) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, ENDING_RL1C, *map(str, args)],
                          capture_output=True, text=True, timeout=300,
                          env=None if env is None else {**os.environ, **env})


@pytest.fixture
def program(tmp_path: Path) -> Path:
    path = tmp_path / "crash.rob"
    path.write_text(PROGRAM, encoding="utf-8")
    return path


def test_a_program_that_ends_an_engines_process_is_reduced_to_the_line_that_does(
        program: Path) -> None:
    ran = ending_rl1c("reduce", program, "--engine", "vm-O0", "--engine", KILLER)
    assert ran.returncode == 0, ran.stderr
    assert "Traceback" not in ran.stderr
    assert program.read_text(encoding="utf-8") == PROGRAM
    reduced = program.with_name("crash.reduced.rob")
    assert reduced.read_text(encoding="utf-8") == f"{CRASHING}\n"
    assert re.fullmatch(
        f"reduced {re.escape(str(program))}: 4 lines, 31 bytes -> 1 line, 7 bytes\n"
        f"difference kept: {KILLER}: ended its process \\(signal SIGSEGV\\)\n"
        f"[0-9]+ tests\nwritten: {re.escape(str(reduced))}\n", ran.stdout), ran.stdout


def test_the_engine_first_or_second_its_ending_is_what_is_kept(program: Path) -> None:
    # A candidate on which the engines merely disagree is not the same bug: the reference
    # ending its process, every candidate interesting keeps the line.
    ran = ending_rl1c("reduce", program, "--engine", KILLER, "--engine", "vm-O2",
                      "--out", program.with_name("out.rob"))
    assert ran.returncode == 0, ran.stderr
    assert program.with_name("out.rob").read_text(encoding="utf-8") == f"{CRASHING}\n"


def test_engines_that_agree_and_end_nothing_leave_nothing_to_reduce(program: Path) -> None:
    program.write_text("B=1\nC=2\n", encoding="utf-8")
    ran = ending_rl1c("reduce", program, "--engine", "vm-O0", "--engine", KILLER)
    assert ran.returncode == 1, ran.stderr
    assert f"the engines agree on {program}: nothing to reduce" in ran.stderr


def test_ctrl_c_while_a_case_is_judged_apart_keeps_the_smallest_so_far(
        program: Path, tmp_path: Path) -> None:
    holding = tmp_path / "holding"
    # The engine holds on the program of the crashing line alone, which the lines pass
    # tries after a smaller interesting case (without C= and D=) was found.
    process = subprocess.Popen(
        [sys.executable, ENDING_RL1C, "reduce", str(program), "--engine", "vm-O0",
         "--engine", KILLER], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env={**os.environ, "RL1_TEST_HOLD": str(holding)})
    try:
        deadline = time.monotonic() + 120
        while not holding.exists():
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline
            time.sleep(0.05)
        process.send_signal(signal.SIGINT)
        stdout, stderr = process.communicate(timeout=60)
    finally:
        process.kill()
        process.wait()
    assert process.returncode == 130, stderr
    assert "interrupted (Ctrl-C) with the smallest so far" in stdout
    kept = program.with_name("crash.reduced.rob").read_text(encoding="utf-8")
    assert CRASHING in kept.splitlines() and len(kept) < len(PROGRAM)


@pytest.mark.parametrize(("name", "apart"), [
    ("ast", False), ("vm-O2", False), ("exec:true", False), ("exec-batch-O1:true", False),
    ("c-O1", True)])
def test_cases_are_judged_apart_only_with_an_engine_that_could_end_this_process(
        name: str, apart: bool) -> None:
    engine = engine_named(name)
    assert engine is not None
    assert _may_end_its_process(engine) is apart


def test_no_c_compiler_for_a_c_engine_is_a_message_and_status_2(program: Path,
                                                                 tmp_path: Path) -> None:
    ran = ending_rl1c("reduce", program, "--engine", "vm-O0", "--engine", "c-O1",
                      env={"CC": "/nonexistent/cc", "XDG_CACHE_HOME": str(tmp_path)})
    assert ran.returncode == 2, ran.stderr
    assert ran.stderr == ("rl1c reduce: error: CC='/nonexistent/cc' names "
                          "'/nonexistent/cc', which is no command here; set CC to a C "
                          "compiler, or unset it to use cc, gcc or clang\n")
    assert not program.with_name("crash.reduced.rob").exists()


@pytest.mark.needs_cc
def test_a_crashing_c_vm_is_reduced_to_the_line_that_crashes_it(program: Path,
                                                                tmp_path: Path) -> None:
    library = crashing_c_vm(tmp_path)
    ran = ending_rl1c("--c-library", library, "reduce", program, "--engine", "vm-O0",
                      "--engine", "c-O1")
    assert ran.returncode == 0, ran.stderr
    assert program.with_name("crash.reduced.rob").read_text(encoding="utf-8") == "A=1234\n"
    assert "difference kept: c-O1: ended its process (signal SIGSEGV)\n" in ran.stdout
