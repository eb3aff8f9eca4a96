"""Host instructions per bytecode instruction in the C VM (vm/c/rl1vm.c), with device
calls counted apart from the other instructions, against the goal of issue 26: at most
10 host instructions for each instruction that is not a call.

For bench/corpus/ (with Listing 1) and bench/unseen/, each program on its sensor script
at -O2, with the threaded build (what hosts build) and the switch one (RL1_THREADED=0):
vm/c's conformance runner (`--once`, the Makefile's -O2 runner) runs the programs under
`valgrind --tool=callgrind --dump-instr=yes --collect-jumps=yes`, which counts each
machine instruction executed at each address, and the jumps taken between addresses.
`addr2line -i` names, for each address of rl1_step and the functions it reaches in
rl1vm.c, the source line of `run()` it was compiled from, through any inlined functions
(a helper such as take_event, inlined at a call and at a jump, belongs to the place it
was inlined into). gcc merges code that several cases end with (the jump to the next
instruction above all), which addr2line places in one of them; such code is shared out
by control flow (call_shares): in proportion to the counts of the instructions that
fall into it or jump to it. So the split is by counting, not by a model:

- a call: the instructions of the call case of `run()` (from its first `case` to its
  `NEXT()`, threaded its own jump to the next instruction included) and the block
  before the loop that polls a started call again in a later step;
- dispatch: the head of `run()`'s loop (up to `switch (op)`), which each instruction
  pays alike with the switch, and threaded only at a step's start and near its limit;
  it is shared out evenly over every instruction;
- the rest of rl1_step is the other instructions' cost, with each step's entry and exit.

The embedder's callbacks (vm/c/test/scripted.c) are other functions: not counted. The
sum over the addresses is checked against bench/c_speed.py's count (rl1_step inclusive
less the callbacks), so nothing is lost or counted twice. Calls are not split by kind:
they share one path, and its instructions cannot tell which kind ran them
(bench/c_callcost.py measures each kind on the targets).

    .venv/bin/python bench/c_host_cost.py
"""

from __future__ import annotations

import argparse
import itertools
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from c_speed import (
    C_FOLDER,
    CORPUS,
    callgrind_cost,
    device_calls,
    program_vectors,
    tools_missing,
    write_vectors,
)

ROOT = Path(__file__).resolve().parent.parent
VM_SOURCE = C_FOLDER / "rl1vm.c"
SETS = {"corpus": CORPUS, "unseen": sorted((ROOT / "bench" / "unseen").glob("*.rob"))}
BUILDS = {"threaded": "", "switch": " -DRL1_THREADED=0"}
LEVEL = 2
GOAL = 10


@dataclass(frozen=True)
class Regions:
    """Line ranges of `run()` in rl1vm.c (each inclusive), found from the source's text."""

    loop: range       # the dispatch loop: everything but the step's entry and exit
    dispatch: range   # the loop's head, up to `switch (op)`
    call_case: range  # the call case, from its `default:` to its NEXT()
    resume: range     # before the loop: a started call polled again

    @staticmethod
    def of(source: str) -> Regions:
        lines = source.splitlines()

        def first(pattern: str, after: int = 0) -> int:
            return next(number for number, text in enumerate(lines, 1)
                        if number > after and re.search(pattern, text))

        head = first(r"^\s*for \(;;\) \{")
        call = first(r"^\s*default:$", head)
        return Regions(range(head, first(r"^\s*vm->pc = \(uint16_t\)\(ip - code\);", head)),
                       range(head, first(r"^\s*switch \(op\) \{", head) + 1),
                       range(call, first(r"^\s*ip = next;", call) + 2),
                       range(first(r"^\s*if \(vm->waiting\) \{"), head))

    def kind(self, line: int | None) -> str:
        """Whose the code of a line of `run()` is (None: outside it): the step's entry and
        exit, the loop's head, the poll of a waiting call before the loop, the call case,
        or the other instructions' cases."""
        if line is None or line not in self.loop:
            return "resume" if line is not None and line in self.resume else "steps"
        if line in self.dispatch:
            return "dispatch"
        return "call" if line in self.call_case else "other"


@dataclass(frozen=True)
class Profile:
    """What callgrind counted in rl1_step and the static functions of rl1vm.c."""

    costs: dict[int, int]              # instructions executed at each address
    jumps: dict[tuple[int, int], int]  # (from, to): the jumps taken between two addresses


def position(text: str, last: int) -> int:
    """A callgrind position: absolute, relative (+n, -n) to the last, or * for the last."""
    if text.startswith("0x"):
        return int(text, 16)
    return last if text == "*" else last + int(text)


def profile(out: Path, source: Path) -> Profile:
    """The counts of a callgrind file written with --dump-instr=yes --collect-jumps=yes
    (positions: address, line). A `calls=` line's next line is the callee's inclusive
    cost at the calling instruction: its position counts, its cost does not. A `jump=` or
    `jcnd=` line (taken count, target position) comes before the position of the jump."""
    names: dict[str, str] = {}
    costs: dict[int, int] = {}
    jumps: dict[tuple[int, int], int] = {}
    address = 0
    in_file = counted = skip_next = False
    jump: tuple[int, int] | None = None  # a jump's target and taken count, its source next
    for line in out.read_text(encoding="utf-8").splitlines():
        # files (fl, fi, fe, cfi, cfl) share one table of compressed names, functions
        # (fn, cfn) another
        if found := re.match(r"(c?fl|fi|fe|cfi|c?fn)=\((\d+)\)(?: (.*))?$", line):
            kind, key, name = found.groups()
            table = "function" if kind.endswith("fn") else "file"
            name = names.setdefault(f"{table} {key}", name or "")
            if kind == "fl":
                in_file = name == str(source)
            elif kind == "fn":  # rl1_step and the static functions it alone reaches
                counted = in_file and (name == "rl1_step" or not name.startswith("rl1_"))
            continue
        if line.startswith("calls="):
            skip_next = True
            continue
        if found := re.match(r"(?:jump=(\d+)|jcnd=(\d+)/\d+) (\S+)", line):
            taken = int(found.group(1) or found.group(2))
            jump = (position(found.group(3), address), taken)
            continue
        fields = line.split()
        if not fields or not re.match(r"0x[0-9a-f]+$|[+-]\d+$|\*$", fields[0]):
            continue
        address = position(fields[0], address)
        if jump is not None:
            if counted and jump[1]:
                edge = (address, jump[0])
                jumps[edge] = jumps.get(edge, 0) + jump[1]
            jump = None
        if counted and not skip_next and len(fields) == 3:
            costs[address] = costs.get(address, 0) + int(fields[2])
        skip_next = False
    return Profile(costs, jumps)


def instructions(binary: Path) -> dict[int, tuple[str, int]]:
    """Each instruction of `binary`: its mnemonic and operands, and the next one's address."""
    listing = subprocess.run(["objdump", "-d", "--no-show-raw-insn", str(binary)],
                             check=True, capture_output=True, text=True).stdout
    found = [(int(address, 16), text) for address, text
             in re.findall(r"^\s*([0-9a-f]+):\s+(\S.*)$", listing, re.MULTILINE)]
    return {address: (text, following) for (address, text), (following, _)
            in itertools.pairwise(found)}


def call_shares(profile: Profile, code: dict[int, tuple[str, int]],
                kinds: dict[int, str]) -> dict[int, float]:
    """For each address of the dispatch loop, the part of its count that calls ran.

    gcc merges code that several cases end with (the jump to the next instruction, a
    fault), which addr2line then places in one of them, so a line alone does not say
    whose a count is. Control flow does: an instruction starts where a jump through the
    dispatch table lands (its case's own line says which kind), and every other address
    is run by the instructions that reach it, by falling through or by a jump, in
    proportion to the counts of each way in (the fixed point of those equations)."""
    costs = profile.costs
    ways_in: dict[int, list[tuple[int, int]]] = {address: [] for address in costs}
    jumped_from: dict[int, int] = {}

    def way_in(source: int, target: int, count: int) -> None:
        # from the loop's head or the step's entry, an instruction starts
        if target in ways_in and kinds[source] in ("other", "call", "resume"):
            ways_in[target].append((source, count))

    for (source, target), taken in profile.jumps.items():
        jumped_from[source] = jumped_from.get(source, 0) + taken
        if "*" not in code[source][0]:  # a jump through the table starts an instruction
            way_in(source, target, taken)
    for source, count in costs.items():
        text, following = code[source]
        if not re.search(r"\b(jmp|ret)\b", text):
            way_in(source, following, count - jumped_from.get(source, 0))
    share = {address: 1.0 if kind in ("call", "resume") else 0.0
             for address, kind in kinds.items()}
    for _ in range(100):
        changed = False
        for address in costs:
            if kinds[address] not in ("other", "call"):
                continue
            entered = costs[address] - sum(count for _, count in ways_in[address])
            base = entered * (1.0 if kinds[address] == "call" else 0.0)
            value = (base + sum(count * share[source] for source, count in ways_in[address])
                     ) / costs[address]
            changed |= abs(value - share[address]) > 1e-12
            share[address] = value
        if not changed:
            break
    return share


def run_lines(binary: Path, addresses: list[int]) -> Iterator[tuple[int, int | None]]:
    """For each address: the line of `run()` it comes from (None outside run)."""
    text = subprocess.run(["addr2line", "-a", "-f", "-i", "-e", str(binary),
                           *(hex(a) for a in addresses)], check=True, capture_output=True,
                          text=True).stdout.splitlines()
    index = 0
    for address in addresses:
        assert int(text[index], 16) == address, text[index]
        index += 1
        run_line: int | None = None
        while index < len(text) and not text[index].startswith("0x"):
            function, where = text[index], text[index + 1]
            index += 2
            if function == "run" and where.startswith(f"{VM_SOURCE}:"):
                run_line = int(where.rsplit(":", 1)[1].split()[0])
        yield address, run_line


def measure(binary: Path, vectors_file: Path, executed: int, calls: int, folder: Path,
            regions: Regions) -> str:
    out = folder / "callgrind.out"
    subprocess.run(["valgrind", "--tool=callgrind", "--dump-instr=yes", "--collect-jumps=yes",
                    f"--callgrind-out-file={out}", str(binary), "--once", str(vectors_file)],
                   check=True, capture_output=True)
    counted = profile(out, VM_SOURCE)
    costs = counted.costs
    kinds = {address: regions.kind(line) for address, line in run_lines(binary, sorted(costs))}
    shares = call_shares(counted, instructions(binary), kinds)
    call_cost = sum(costs[address] * shares[address] for address in costs)
    steps = sum(costs[address] for address, kind in kinds.items() if kind == "steps")
    dispatch = sum(costs[address] for address, kind in kinds.items() if kind == "dispatch")
    total = sum(costs.values())
    expected = callgrind_cost(binary, vectors_file, folder)
    assert total == expected, f"{total:,} instructions by address, {expected:,} by function"
    share = dispatch / executed
    per_call = call_cost / calls + share
    others = executed - calls
    per_other = (total - steps - call_cost - share * calls) / others
    return (f"{per_other:6.2f} per other instruction ({others:,})   (goal: at most {GOAL})"
            f"   {per_call:7.1f} per call ({calls:,})   [{total:,} in all: "
            f"{steps:,} the steps' entries and exits]")


def main() -> int:
    argparse.ArgumentParser(description=__doc__.split("\n\n")[0]).parse_args()
    if tools_missing("c_host_cost.py", ("valgrind", "addr2line", "callgrind_annotate", "make")):
        return 2
    regions = Regions.of(VM_SOURCE.read_text(encoding="utf-8"))
    host_cc = shutil.which("gcc") or "cc"
    print(f"host instructions per bytecode instruction, the programs at -O{LEVEL} "
          "(callgrind, each address's count placed by addr2line -i and its ways in)")
    with tempfile.TemporaryDirectory(prefix="rl1-c-host-cost-") as scratch:
        folder = Path(scratch)
        binaries = {}
        for build, flags in BUILDS.items():
            (folder / build).mkdir()
            binaries[build] = folder / build / "vectors-fast"
            # -no-pie: callgrind's addresses are then the file's, which addr2line reads
            subprocess.run(["make", "-s", "-C", str(C_FOLDER), f"BUILD={folder / build}",
                            f"HOST_CC={host_cc} -no-pie{flags}", str(binaries[build])],
                           check=True)
        for name, paths in SETS.items():
            if not paths:
                continue
            vectors = program_vectors(paths, LEVEL)
            vectors_file = folder / f"{name}.txt"
            executed = write_vectors(vectors_file, vectors)
            calls = device_calls(vectors)
            for build, binary in binaries.items():
                figures = measure(binary, vectors_file, executed, calls, folder, regions)
                print(f"   {name} ({len(vectors)} programs), {build:8} {figures}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
