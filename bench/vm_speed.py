"""VM speed: a loop-heavy RL/I program on the reference VM and on the C VM (through
ctypes, when this machine can build it), against the same computation written as plain
Python and run by CPython, in the same process.

Prints each VM's instructions per second and time, and the ratio of CPython's time to
each VM's. The reference VM has no goal: it is written to be read beside the spec, one
instruction at a time, and speed is the C VM's job (`rl1c run --engine c`; its own
figures against Lua are bench/c_speed.py's). What its speed costs the fuzzer, whose
programs are short, is `rl1c fuzz`'s programs per second.

    .venv/bin/python bench/vm_speed.py [--repeat 5]
"""

from __future__ import annotations

import argparse

from timing import best_time

from rl1.compiler.backend.driver import compile_text
from rl1.vm.faults import DEFAULT_BUDGET, RunResult
from rl1.vm.hardware import Blocking
from rl1.vm.machine import Machine
from rl1.vm.native import BuildError, NativeMachine, library, load
from rl1.vm.scripted import ScriptedDevice
from rl1.vm.verifier import verify

OUTER, INNER = 100, 1000

PROGRAM = f"""' nested counting loops with 16-bit arithmetic
N={OUTER}
:10 M={INNER}
:20 A=A+M&$3FF; B=B+A>2^M; C=C-B|1
M--; ?M>#20
N--; ?N>#10
(END)
"""


def python_equivalent() -> tuple[int, int, int]:
    """PROGRAM as a Python programmer would write it, wrapping where a sum can overflow."""
    a = b = c = 0
    n = OUTER
    while n > 0:
        m = INNER
        while m > 0:
            a = (((a + m + 0x8000) & 0xFFFF) - 0x8000) & 0x3FF
            b = ((((b + a + 0x8000) & 0xFFFF) - 0x8000) >> 2) ^ m
            c = (((c - b + 0x8000) & 0xFFFF) - 0x8000) | 1
            m -= 1
        n -= 1
    return a, b, c


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs of each; the best counts")
    options = parser.parse_args()

    compilation = compile_text(PROGRAM, "vm_speed.rob")
    assert compilation.output is not None, compilation.diagnostics
    data = compilation.output
    program = verify(data)

    counted = Machine(program, Blocking(ScriptedDevice()))
    result = counted.run()
    assert result.fault is None, result.fault
    named = result.named()
    expected = python_equivalent()
    assert (named["A"], named["B"], named["C"]) == expected, (named, expected)
    instructions = counted.executed

    vm_time = best_time(lambda: Machine(program, Blocking(ScriptedDevice())).run(), options.repeat)
    python_time = best_time(python_equivalent, options.repeat)
    print(f"instructions per run:     {instructions:,}")
    print(f"reference VM:             {vm_time * 1000:8.1f} ms, "
          f"{instructions / vm_time / 1e6:.2f} M instructions/s")
    c_time: float | None = None
    try:
        c_vm = load(library())
    except BuildError as error:
        print(f"C VM:                     not measured: {error}")
    else:
        def run_c() -> RunResult:
            return NativeMachine(data, Blocking(ScriptedDevice()), DEFAULT_BUDGET, c_vm).run()

        assert run_c() == result, "the C VM disagrees with the reference"
        c_time = best_time(run_c, options.repeat)
        print(f"C VM:                     {c_time * 1000:8.1f} ms, "
              f"{instructions / c_time / 1e6:.2f} M instructions/s")
    print(f"CPython, same work:       {python_time * 1000:8.1f} ms")
    print(f"ratio CPython/VM time:    {python_time / vm_time:.2f} (reference VM)"
          + ("" if c_time is None else f", {python_time / c_time:.2f} (C VM)"))


if __name__ == "__main__":
    main()
