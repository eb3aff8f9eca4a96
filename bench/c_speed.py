"""The C VM's speed (vm/c/), against the goals of issue 13, each as a ratio to a
reference run in this same run:

1. Host speed against Lua 5.4 (Debian's lua5.4) running the same computation, a loop
   nest of 16-bit arithmetic: both as whole processes (the C side is vm/c's conformance
   runner, `--once`, on the compiled program, checking its result), the best of
   --repeat runs, each one's start-up (an empty program, an empty script) subtracted.
   Goal: the C VM at least 2x Lua's speed.
2. Host instructions per bytecode instruction, counted by `valgrind --tool=callgrind`
   (independent of the machine's load): the instructions inside rl1_step less those in
   the scripted device's callbacks, over the instructions the VM executed, for the
   computation and for the optimizer's corpus (Listing 1 and bench/corpus/, each on its
   sensor script) at -O0 and -O2. Goal: at most 10 on the corpus.
3. Verification of a 64 KB program: the time rl1_load takes with its jump-target bitmap
   and by rescanning, against the Python verifier on the same file, and the memory it
   needs.

    .venv/bin/python bench/c_speed.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import ctypes
import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from timing import best_time

from rl1.compiler.backend.driver import compile_text
from rl1.vm import ilc, isa, native
from rl1.vm.drive import drive
from rl1.vm.hardware import Blocking
from rl1.vm.language import Feature
from rl1.vm.machine import Machine
from rl1.vm.scripted import LOST, ScriptedDevice, parse_script
from rl1.vm.verifier import verify

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "spec" / "vectors"))
from generate import render_text  # noqa: E402

C_FOLDER = ROOT / "vm" / "c"
CORPUS = [ROOT / "examples" / "sample.rob", *sorted((ROOT / "bench" / "corpus").glob("*.rob"))]
BUDGET = 2**31 - 1
SPEED_LEVELS = (0, 1, 2)  # -O1: what rl1c compiles at unless told
OUTER = 30000  # iterations of the computation's outer loop (200 inner ones each)

# The same computation twice: A=((A^C)+B)&4095 over C=200..1 for B=OUTER..1. The AND
# keeps 12 bits, which a 16-bit wrap leaves alone, so Lua's integers give the same A.
COMPUTATION = f"""A=0
B={OUTER}
:10 C=200
:20 A=A^C+B&4095
C--
?C>#20
B--
?B>#10
"""
LUA = f"""local a, b = 0, {OUTER}
repeat
  local c = 200
  repeat
    a = ((a ~ c) + b) & 4095
    c = c - 1
  until not (c > 0)
  b = b - 1
until not (b > 0)
print(a)
"""
# Trace entries that no call instruction made: the device's stop after a fault, a loss.
NOT_CALLS = ("STOP", LOST)
# The callbacks of vm/c/test/scripted.c: their cost is the device's, not the VM's.
CALLBACKS = ("begin", "call", "start", "poll", "stop", "end")


def vector(name: str, data: bytes, sensors: dict[str, object]) -> dict[str, object]:
    """A run vector of `data` on `sensors` (spec/vectors/README.md), run by the
    reference VM, for the C runner to run again and check."""
    device = ScriptedDevice(parse_script(sensors))
    machine = Machine(verify(data), Blocking(device), BUDGET)
    result = drive(machine, device)
    fault = result.fault
    return {"name": name, "budget": BUDGET, "ilc": data.hex(), "ilc_stripped": data.hex(),
            "sensors": sensors, "status": "ok" if fault is None else fault.kind.code,
            "exit_status": 0 if fault is None else fault.kind.exit_status,
            "fault_line": (fault.line or 0) if fault is not None else 0,
            "executed": machine.executed, "variables": list(result.variables),
            "trace": [{"time": entry.time, "call": entry.call, "args": list(entry.args),
                       "result": list(entry.result or ())} for entry in device.trace]}


def program_vectors(paths: Sequence[Path], level: int) -> list[dict[str, object]]:
    """A run vector of each program compiled at -O`level`, on its sensor script beside
    it (NAME.sensors.json), or on none."""
    vectors = []
    for path in paths:
        sensors_path = path.with_suffix(".sensors.json")
        sensors = (json.loads(sensors_path.read_text(encoding="utf-8"))
                   if sensors_path.exists() else {})
        vectors.append(vector(path.stem, compiled(path.read_text(encoding="utf-8"),
                                                  path.name, level), sensors))
    return vectors


def device_calls(vectors: list[dict[str, object]]) -> int:
    """The call instructions the vectors' runs executed: their traces' entries, less
    those no call made."""
    return sum(1 for v in vectors if isinstance(trace := v["trace"], list)
               for entry in trace if entry["call"] not in NOT_CALLS)


def compiled(source: str, name: str, level: int = 0) -> bytes:
    output = compile_text(source, name, level=level).output
    assert output is not None, f"{name} does not compile"
    return output


def whole_processes(commands: Sequence[Sequence[str]], repeat: int) -> list[float]:
    """The best wall time of each command (which must succeed) over `repeat` rounds; a
    round runs every command once, so that a load on the machine weighs on all alike."""
    best = [float("inf")] * len(commands)
    for _ in range(repeat):
        for index, command in enumerate(commands):
            start = time.perf_counter()
            subprocess.run(command, check=True, capture_output=True)
            best[index] = min(best[index], time.perf_counter() - start)
    return best


def callgrind_cost(runner: Path, text_file: Path, folder: Path) -> int:
    """Host instructions inside rl1_step, less the scripted device's callbacks."""
    out = folder / "callgrind.out"
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                    str(runner), "--once", str(text_file)], check=True, capture_output=True)
    report = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100",
                             "--auto=no", str(out)], check=True, capture_output=True,
                            text=True).stdout
    inclusive: dict[str, int] = {}
    for line in report.splitlines():  # "12,345 (1.00%)  /path/file.c:function [binary]"
        found = re.match(r"\s*([\d,]+) \([^)]*\)\s+(\S+\.c):(\w+)", line)
        if found:
            where = f"{Path(found.group(2)).name}:{found.group(3)}"
            inclusive[where] = max(inclusive.get(where, 0), int(found.group(1).replace(",", "")))
    device = sum(inclusive.get(f"scripted.c:{name}", 0) for name in CALLBACKS)
    return inclusive["rl1vm.c:rl1_step"] - device


def write_vectors(path: Path, vectors: list[dict[str, object]]) -> int:
    path.write_text(render_text("bench", vectors), encoding="ascii")
    return sum(int(str(v["executed"])) for v in vectors)


def speed(runner: Path, folder: Path, repeat: int) -> None:
    lua_work, lua_empty = folder / "computation.lua", folder / "empty.lua"
    lua_work.write_text(LUA, encoding="ascii")
    lua_empty.write_text("", encoding="ascii")
    lua_said = subprocess.run(["lua5.4", str(lua_work)], check=True, capture_output=True,
                              text=True).stdout.strip()
    empty = folder / "empty.txt"
    write_vectors(empty, [vector("empty", compiled("(END)\n", "e.rob"), {})])
    commands = [["lua5.4", str(lua_work)], ["lua5.4", str(lua_empty)],
                [str(runner), "--once", str(empty)]]
    executed = []
    for level in SPEED_LEVELS:
        data = compiled(COMPUTATION, "c.rob", level)
        answer = Machine(verify(data), Blocking(ScriptedDevice()), BUDGET).run().variables[0]
        assert lua_said == str(answer), f"Lua computes {lua_said}, the VM {answer}"
        work = folder / f"computation-O{level}.txt"
        executed.append(write_vectors(work, [vector("computation", data, {})]))
        commands.append([str(runner), "--once", str(work)])
    lua_time, lua_start, c_start, *c_times = whole_processes(commands, repeat)
    lua_net = lua_time - lua_start
    print(f"1. the computation ({OUTER} x 200 iterations; the best of {repeat} rounds, "
          "start-up subtracted)")
    print(f"   Lua 5.4       {lua_net * 1000:8.1f} ms  ({lua_time * 1000:.1f} - "
          f"{lua_start * 1000:.1f})")
    for level, c_time, count in zip(SPEED_LEVELS, c_times, executed, strict=True):
        c_net = c_time - c_start
        print(f"   C VM, -O{level}    {c_net * 1000:8.1f} ms  ({c_time * 1000:.1f} - "
              f"{c_start * 1000:.1f}; {count:,} instructions, {count / c_net / 1e6:.0f} M/s): "
              f"{lua_net / c_net:.2f}x Lua's speed   (goal: at least 2x)")


def instructions(runner: Path, folder: Path) -> None:
    print("2. host instructions per bytecode instruction (callgrind, rl1_step without the "
          "device's callbacks)")
    for level in (0, 2):
        computation = folder / f"small-O{level}.txt"
        executed = write_vectors(computation, [vector("computation", compiled(
            COMPUTATION.replace(str(OUTER), "300"), "c.rob", level), {})])
        cost = callgrind_cost(runner, computation, folder)
        print(f"   the computation at -O{level}       {cost / executed:6.2f}  "
              f"({cost:,} / {executed:,})")
    for level in (0, 2):
        vectors = program_vectors(CORPUS, level)
        corpus = folder / f"corpus-O{level}.txt"
        executed = write_vectors(corpus, vectors)
        calls = device_calls(vectors)
        cost = callgrind_cost(runner, corpus, folder)
        print(f"   the corpus at -O{level} ({len(vectors)} programs) {cost / executed:6.2f}  "
              f"({cost:,} / {executed:,}, {calls:,} of them device calls)   "
              "(goal: at most 10)")


def big_program() -> bytes:
    """A file with 65,533 bytes of code: 5,461 blocks of LDI, STV, ADDI and a jump back
    to the block's start, then END."""
    code = bytearray()
    info = isa.BY_NAME
    while len(code) + 12 < 0xFFFF:
        start = len(code)
        code += isa.encode(info["LDI"], (5,)) + isa.encode(info["STV"], (0,))
        code += isa.encode(info["ADDI"], (1,)) + isa.encode(info["JGT"], (0, start))
    code += isa.encode(info["END"], ())
    return ilc.encode(ilc.Image(bytes(code), {}, frozenset(Feature)))


def verification(library: ctypes.CDLL, repeat: int) -> None:
    data = big_program()
    code_size = int.from_bytes(data[14:16], "little")
    bitmap = (code_size + 7) // 8
    offset = ctypes.c_uint32(0)

    def load(bitmap_size: int) -> None:
        assert library.rl1_test_load(data, len(data), bitmap_size, ctypes.byref(offset)) == 0

    with_bitmap = best_time(lambda: load(bitmap), repeat)
    rescan = best_time(lambda: load(0), max(1, repeat // 5))
    python = best_time(lambda: verify(data), max(1, repeat // 5))
    print(f"3. verifying a {len(data):,}-byte file ({code_size:,} bytes of code, "
          f"{code_size // 12:,} jumps)")
    print(f"   rl1_load with a {bitmap:,}-byte bitmap  {with_bitmap * 1000:8.2f} ms")
    print(f"   rl1_load rescanning, no memory      {rescan * 1000:8.2f} ms  "
          f"({rescan / with_bitmap:.0f}x the bitmap's time)")
    print(f"   the Python verifier                 {python * 1000:8.2f} ms  "
          f"({python / with_bitmap:.0f}x the C loader's time)")
    print(f"   memory: the bitmap ({bitmap:,} bytes, scratch, or none), rl1_program "
          f"({ctypes.sizeof(ctypes.c_void_p) * 4 + 18} bytes here) and rl1_load's stack "
          "(bench/c_size.py); nothing else")


def tools_missing(script: str, tools: Sequence[str]) -> bool:
    """Whether this machine lacks any of the tools bench/`script` runs; if so, say
    which, and how to install them."""
    missing = [tool for tool in tools if shutil.which(tool) is None]
    if missing:
        print(f"bench/{script} needs {', '.join(missing)} (vm/c/install-tools installs "
              "them on Debian)", file=sys.stderr)
    return bool(missing)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs of each; the best counts")
    options = parser.parse_args()
    if tools_missing("c_speed.py", ("lua5.4", "valgrind", "callgrind_annotate", "make")):
        return 2
    with tempfile.TemporaryDirectory(prefix="rl1-c-speed-") as scratch:
        folder = Path(scratch)
        runner = folder / "vectors-fast"
        subprocess.run(["make", "-s", "-C", str(C_FOLDER), f"BUILD={folder}", str(runner)],
                       check=True)
        speed(runner, folder, options.repeat)
        instructions(runner, folder)
        verification(native.load(native.library(folder)), options.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
