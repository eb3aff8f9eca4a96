"""Peak memory of `rl1c` on the largest inputs it accepts: `rl1c sim` on the worst valid
worlds (the longest time limit, the shortest tracing interval), against the bound of
spec/simulator.md (200 MB), and `rl1c check`, `rl1c compile` and `rl1c check --fix` on
8 MiB sources of several shapes, in bytes per source byte, against the bound of
spec/language.md (64).

Each figure is the peak resident set of one `rl1c` process (os.wait4's ru_maxrss), with
the peak of `rl1c check` on an empty file printed as the reference (the interpreter and
the modules). A run that has not ended after --seconds is stopped, and its peak so far
is printed with "(stopped)".

    .venv/bin/python bench/memory.py [--only sim|source] [--command check|compile|compile-s|fix]
                                     [--match TEXT] [--seconds 300]
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1] / "tests"))

from support.block_shapes import BLOCK_SHAPES  # tests/ is put on the path just above

RL1C = [sys.executable, "-c", "import sys; from rl1.compiler.cli.main import rl1c; "
        "sys.argv[0] = 'rl1c'; sys.exit(rl1c())"]
MIB = 2**20
SOURCE_BYTES = 8 * MIB

# The program drives on for as long as the world lets it: a straight run at the slowest
# speed, then waits of 10 s (few calls, so that the figure is the simulator's own).
DRIVE_ON = "(MOV 1,1)\n:10 (TIM 100); #10\n"


def world(trace_interval: float, time_limit: float, delay: float = 0.0) -> str:
    """A floor as large as a world allows, the vehicle in the middle heading along it."""
    return (f"[floor]\nsize = [1000000, 1000000]\n\n"
            f"[start]\nx = 1000\ny = 500000\nheading = 0\n\n"
            f"[vehicle]\ntrace_interval = {trace_interval!r}\n\n"
            f"[noise]\ndelay = {delay!r}\n\n"
            f"[limits]\ntime = {time_limit!r}\n")


def peak(arguments: list[str], seconds: float) -> tuple[float, str]:
    """The peak resident set in MB of `rl1c ARGUMENTS`, and how it ended."""
    process = subprocess.Popen([*RL1C, *arguments], stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, start_new_session=True)
    deadline = time.monotonic() + seconds
    while True:
        pid, status, usage = os.wait4(process.pid, os.WNOHANG)
        if pid:
            break
        if time.monotonic() > deadline:
            os.killpg(process.pid, signal.SIGKILL)
            pid, status, usage = os.wait4(process.pid, 0)
            return usage.ru_maxrss / 1024, "(stopped)"
        time.sleep(0.05)
    ending = f"exit {os.waitstatus_to_exitcode(status)}"
    return usage.ru_maxrss / 1024, ending


def sim_cases(folder: Path, seconds: float, match: str) -> None:
    program = folder / "drive.rob"
    program.write_text(DRIVE_ON)
    print("rl1c sim: peak resident MB (bound: 200)")
    # The worst valid worlds: the longest time limit, and the most tracing ticks a run
    # may take (world.MAX_TICKS) with the longest sensor delay; then two that were valid
    # before the world's bounds (issue 23), which the loader now refuses.
    cases = [
        ("default interval 0.05 s, time limit 24 h", world(0.05, 86400.0)),
        ("interval 1e-3 s, delay 10 s, limit 2,000 s", world(1e-3, 2000.0, 10.0)),
        ("interval 1e-4 s, time limit 24 h", world(1e-4, 86400.0)),
        ("interval 1e-9 s, time limit 24 h", world(1e-9, 86400.0)),
    ]
    for name, text in cases:
        if match not in name:
            continue
        path = folder / "case.world.toml"
        path.write_text(text)
        started = time.monotonic()
        megabytes, ending = peak(["sim", str(program), "--world", str(path), "--format",
                                  "json", "--svg", str(folder / "run.svg"), "--html",
                                  str(folder / "run.html")], seconds)
        sizes = ", ".join(f"{kind} {(folder / f'run.{kind}').stat().st_size / MIB:.1f} MiB"
                          for kind in ("svg", "html") if (folder / f"run.{kind}").exists())
        print(f"  {name:<44} {megabytes:8.1f} MB  {ending} after "
              f"{time.monotonic() - started:.0f} s  {sizes}")
        for kind in ("svg", "html"):
            (folder / f"run.{kind}").unlink(missing_ok=True)


def sources() -> list[tuple[str, bytes, bytes]]:
    """8 MiB sources that are each costly in their own way, as their first line and the
    line each repeats."""
    statements = b";".join([b"A=1"] * 4999)  # 19,999 characters of code
    return [
        ("lines of 19,999 characters", b"", statements + b"\n"),
        ("`A=1` lines", b"", b"A=1\n"),
        ("lines with a syntax error", b"", b"A=1 B=2\n"),
        # The program-wide rules' costliest: a block a line, and a block of a million
        # lines whose effects are combined as they come.
        ("`(END)` lines, a block each", b"", b"(END)\n"),
        ("`t=1` lines, reserved writes", b"", b"t=1\n"),
        # a diagnostic of a program-wide rule a line (W0401: `s` may be unset)
        ("`A=s` lines, unset reads", b"", b"A=s\n"),
        # a block every few bytes, each shape tests/backend/test_compile_memory.py holds
        # to the bound: conditional jumps, jumps back to the first line, labels, a
        # handler's ends
        *((shape.name, shape.head.encode(), shape.unit.encode())
          for shape in BLOCK_SHAPES.values()),
        ("`#01` lines, no `:01`: an E0203 each", b"", b"#01\n"),
        # a block for every three bytes (and an E0202 a line): above the bound
        ("`#1` lines, a block each 3 bytes", b"", b"#1\n"),
        # a fix a line, all made in one round (and lines with a syntax error above)
        ("`(mov 3,3)` lines, a fix each", b"", b"(mov 3,3)\n"),
    ]


def write_filled(path: Path, head: bytes, line: bytes) -> int:
    """Write `head`, then `line` as many times as SOURCE_BYTES holds, into `path`, a few
    at a time, and return the bytes written. A child's peak is at least the peak of this
    process when it started the child (Linux gives a child's ru_maxrss the larger of its
    own and that of the process it replaced), so this one never holds a source: holding
    them all made every figure at least this process's 37 MB (53 MB with five sources)."""
    count = (SOURCE_BYTES - len(head)) // len(line)
    chunk = max(1, 65536 // len(line))
    with path.open("wb") as file:
        file.write(head)
        for written in range(0, count, chunk):
            file.write(line * min(chunk, count - written))
    return len(head) + count * len(line)


def source_cases(folder: Path, seconds: float, match: str, commands: list[str]) -> None:
    # compile -s: without the debug section, whose line numbers end at 65,535, so that
    # 8 MiB of short lines compile (compile alone refuses them, E0191)
    arguments = {"check": ["check"], "compile": ["compile", "-o", str(folder / "big.ilc")],
                 "compile-s": ["compile", "-s", "-o", str(folder / "big.ilc")],
                 "fix": ["check", "--fix"]}
    empty = folder / "empty.rob"
    empty.write_bytes(b"")
    reference, _ = peak(["check", str(empty)], seconds)
    labels = {"check": "check", "compile": "compile", "compile-s": "compile -s",
              "fix": "check --fix"}
    print(f"rl1c {', '.join(labels[one] for one in commands)} on 8 MiB sources: peak "
          f"resident MB, and bytes per source byte above `rl1c check` on an empty file "
          f"({reference:.1f} MB); bound: 64")
    for name, head, line in sources():
        if match not in name:
            continue
        path = folder / "big.rob"
        for command in commands:
            size = write_filled(path, head, line)  # anew: --fix rewrites it
            started = time.monotonic()
            megabytes, ending = peak([*arguments[command], str(path)], seconds)
            per_byte = (megabytes - reference) * MIB / size
            print(f"  {labels[command]:<11} {name:<40} {megabytes:8.1f} MB {per_byte:6.1f} B/B"
                  f"  {ending} after {time.monotonic() - started:.0f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=("sim", "source"))
    parser.add_argument("--command", choices=("check", "compile", "compile-s", "fix"),
                        help="only this command on the sources")
    parser.add_argument("--match", default="", help="only the cases whose name holds this")
    parser.add_argument("--seconds", type=float, default=300.0,
                        help="stop a run after this long and print its peak so far")
    options = parser.parse_args()
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        if options.only in (None, "sim"):
            sim_cases(folder, options.seconds, options.match)
        if options.only in (None, "source"):
            commands = [options.command] if options.command else ["check", "compile"]
            source_cases(folder, options.seconds, options.match, commands)


if __name__ == "__main__":
    main()
