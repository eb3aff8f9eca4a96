"""What one device call costs inside the C VM (vm/c/rl1vm.c) on the firmware targets,
the embedder's callbacks left out, against the goals of issue 26: at most 60 Cortex-M3
instructions for a call with no argument plus at most 8 an argument, at most 250
ATmega328P cycles for KYC.

For each call kind the bench builds two programs: a few variables set (the call's
arguments), then N copies of the call, then END; and the same without the calls. Each is
linked with the VM, the loader and vm/c/test/callcost.c (a device whose callbacks answer
done at once) into a firmware image built at -Os as firmware is, and run:

- Cortex-M3 (lm3s6965evb) under qemu-system-arm with `-singlestep -d exec,nochain`
  (`-one-insn-per-tb` from qemu 8.1): one log line for each instruction the machine
  runs. The bench counts the lines between
  callcost_begin and callcost_end (around rl1_step) whose function is not one of the
  callbacks (callcost_hw_*): the machine's own instructions, exact.
- ATmega328P under simavr: the firmware counts the cycles of rl1_step with Timer1 at the
  CPU's clock, and those of one callback reached the way the VM reaches it (an indirect
  call through the hardware table), which the bench subtracts once for each callback a
  call makes (1 for an immediate call, start and poll for one started and polled).

A call's cost is (run with N calls - run without) / N: dispatch, decoding, the
arguments' range checks, the callbacks' invocation, writing the results, and the event
point after it. With --by-line, each Cortex-M3 kind's count is also placed by line of
vm/c (each address's (count with N calls - without) / N, named by addr2line in the image,
which is built with -g: the same code), the source line beside it, so that what a call
spends is read where it is written.

    .venv/bin/python bench/c_callcost.py [--calls N] [--build FOLDER] [--by-line]

Needs arm-none-eabi-gcc, qemu-system-arm, avr-gcc and simavr (vm/c/install-tools); a
target without its tools is skipped, and says so.
"""

from __future__ import annotations

import argparse
import collections
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from rl1.vm import ilc, isa
from rl1.vm.language import VARIABLES, Feature

VM_C = Path(__file__).resolve().parent.parent / "vm" / "c"
WARN = ["-I../../spec", "-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror",
        "-Wconversion", "-Wsign-conversion"]
SOURCES = ["rl1vm.c", "rl1vm_load.c", "test/callcost.c"]
GOAL_NO_ARGUMENT, GOAL_PER_ARGUMENT, GOAL_AVR_KYC = 60, 8, 250


@dataclass(frozen=True)
class Kind:
    label: str
    mnemonic: str           # the opcode's name in vm/isa.py
    values: tuple[int, ...]  # each argument's value
    variables: bool         # each passed in a variable of its own (a, b, c), or constants
    started: bool           # started and polled (two callbacks), or immediate (one)

    @property
    def m3_goal(self) -> int:
        return GOAL_NO_ARGUMENT + GOAL_PER_ARGUMENT * len(self.values)


# The compact calls (MOVS, MVIS: a byte an argument) are what -O2 writes for these.
KINDS = (Kind("KYC", "KYC", (), False, False),
         Kind("IMG (started and polled)", "IMG", (), False, True),
         Kind("MOV 3, -4 (two constants)", "MOV", (3, -4), False, False),
         Kind("MOV a, b (two variables)", "MOV", (3, -4), True, False),
         Kind("MOVS 3, -4 (compact)", "MOVS", (3, -4), False, False),
         Kind("MOVS a, b (compact)", "MOVS", (3, -4), True, False),
         Kind("MVI 3, -4, 100 (constants)", "MVI", (3, -4, 100), False, True),
         Kind("MVI a, b, c (three variables)", "MVI", (3, -4, 100), True, True),
         Kind("MVIS 3, -4, 100 (compact)", "MVIS", (3, -4, 100), False, True),
         Kind("MVIS a, b, c (compact)", "MVIS", (3, -4, 100), True, True))


def program(kind: Kind, calls: int) -> bytes:
    """The .ilc file: the arguments' variables set (a, b, c), then `calls` calls, END."""
    by_name = {info.name: info for info in isa.OPCODES.values()}
    if kind.variables:
        variables = [VARIABLES.index(name) for name in "abc"[:len(kind.values)]]
        code = b"".join(isa.encode(by_name["MOVI"], (variable, value))
                        for variable, value in zip(variables, kind.values, strict=True))
        args = tuple(isa.Arg(True, variable) for variable in variables)
    else:
        code, args = b"", tuple(isa.Arg(False, value) for value in kind.values)
    code += isa.encode(by_name[kind.mnemonic], (), args) * calls + isa.encode(by_name["END"])
    return ilc.encode(ilc.Image(code, {}, frozenset(Feature)))


def c_source(data: bytes) -> str:
    body = ",\n".join("    " + ", ".join(f"0x{byte:02x}" for byte in data[i:i + 12])
                      for i in range(0, len(data), 12))
    return ('#include "target.h"\n\n'
            f"const uint8_t callcost_program[{len(data)}] TARGET_FLASH = {{\n{body}\n}};\n"
            f"const uint16_t callcost_program_size = {len(data)}u;\n")


def build(compiler: list[str], build_dir: Path, name: str, data: bytes) -> Path:
    source = build_dir / f"{name}.c"
    source.write_text(c_source(data), encoding="utf-8")
    elf = build_dir / f"{name}.elf"
    subprocess.run([*compiler, *WARN, "-Itest", "-o", str(elf), *SOURCES, str(source)],
                   cwd=VM_C, check=True)
    return elf


ARM = ["arm-none-eabi-gcc", "-mcpu=cortex-m3", "-mthumb", "-Os", "-g", "-ffreestanding",
       "-nostdlib", "-T", "test/arm.ld", "test/arm_start.c"]
AVR = ["avr-gcc", "-mmcu=atmega328p", "-Os", "-DRL1_READ_BYTE(p)=pgm_read_byte(p)",
       "-include", "avr/pgmspace.h", "-fno-tree-switch-conversion",
       "-DTARGET_FLASH=PROGMEM", "test/avr_start.c"]
# qemu's exec log: "Trace 0: 0x... [cs_base/pc/flags/cflags] function"
TRACE = re.compile(r"^Trace \d+: \S+ \[[0-9a-f]+/([0-9a-f]+)/[0-9a-f]+/[0-9a-f]+\] (\S*)")


def one_instruction_a_block() -> str:
    """qemu's option for one instruction a translation block: -singlestep until 8.1
    renamed it."""
    usage = subprocess.run(["qemu-system-arm", "-help"], capture_output=True, text=True,
                           check=False).stdout
    return "-one-insn-per-tb" if "-one-insn-per-tb" in usage else "-singlestep"


def m3_instructions(elf: Path) -> collections.Counter[int]:
    """The instructions the Cortex-M3 runs in rl1_step, the callbacks' left out: how many
    times each address ran."""
    log = elf.with_suffix(".log")
    run = subprocess.run(["qemu-system-arm", "-M", "lm3s6965evb", "-nographic",
                          "-semihosting-config", "enable=on,target=native",
                          one_instruction_a_block(), "-d", "exec,nochain", "-D", str(log),
                          "-kernel", str(elf)],
                         stdin=subprocess.DEVNULL, capture_output=True, text=True,
                         timeout=300, check=False)
    if run.returncode != 0:
        raise RuntimeError(f"{elf.name} failed under qemu: {run.stdout}{run.stderr}")
    counting, count = False, collections.Counter[int]()
    with log.open(encoding="utf-8", errors="replace") as lines:
        for line in lines:
            match = TRACE.match(line)
            if match is None:
                continue
            function = match.group(2)
            if function == "callcost_end":
                return count
            if function == "callcost_begin":
                counting = True
            elif counting and not function.startswith("callcost_hw_"):
                count[int(match.group(1), 16)] += 1
    raise RuntimeError(f"{log}: no callcost_end in qemu's log")


def by_line(elf: Path, per_call: dict[int, float]) -> list[str]:
    """Each line of vm/c whose instructions a call ran, in the order of the files: how many
    a call, the line's place and its text. addr2line names an inlined helper's own line
    (rl1vm.h's rl1_flash_u16 for the descriptor's load), not the line it is used at."""
    addresses = sorted(per_call)
    named = subprocess.run(["arm-none-eabi-addr2line", "-e", str(elf),
                            *(hex(address) for address in addresses)],
                           check=True, capture_output=True, text=True).stdout.splitlines()
    lines: collections.defaultdict[tuple[str, int], float] = collections.defaultdict(float)
    for address, place in zip(addresses, named, strict=True):
        file, _, number = place.rpartition(":")
        lines[Path(file).name, int(number.split()[0]) if number[:1].isdigit() else 0] += (
            per_call[address])
    texts = {name: (VM_C / name).read_text(encoding="utf-8").splitlines()
             for name in ("rl1vm.c", "rl1vm.h") if any(file == name for file, _ in lines)}
    return [f"    {count:5.1f}  {file}:{number:<5} "
            f"{texts[file][number - 1].strip()[:60] if file in texts and number else ''}"
            for (file, number), count in sorted(lines.items()) if round(count, 1)]


def avr_cycles(elf: Path, callbacks: int) -> int:
    """The cycles the ATmega328P spends in rl1_step, `callbacks` callbacks' left out."""
    run = subprocess.run(["simavr", "-m", "atmega328p", "-f", "16000000", str(elf)],
                         capture_output=True, text=True, timeout=300, check=False,
                         errors="replace")
    match = re.search(r"callcost: (\d+) (\d+)", run.stdout + run.stderr)
    if match is None:
        raise RuntimeError(f"{elf.name} failed under simavr: {run.stdout}{run.stderr}")
    return int(match.group(1)) - callbacks * int(match.group(2))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--calls", type=int, default=10, help="calls in a program (10)")
    parser.add_argument("--build", type=Path, default=VM_C / "build" / "callcost")
    parser.add_argument("--by-line", action="store_true",
                        help="place each Cortex-M3 count by line of vm/c")
    options = parser.parse_args()
    options.build.mkdir(parents=True, exist_ok=True)
    build_dir = options.build.resolve()
    have_arm = all(shutil.which(tool) for tool in ("arm-none-eabi-gcc", "qemu-system-arm"))
    have_avr = all(shutil.which(tool) for tool in ("avr-gcc", "simavr"))
    print(f"a call's cost in rl1_step, callbacks excluded: (N = {options.calls} calls - none)"
          f" / N, -Os")
    print(f"{'call kind':<32} {'Cortex-M3 instructions':>22} {'goal':>5}   "
          f"{'ATmega328P cycles':>17} {'goal':>5}")
    status = 0
    for kind in KINDS:
        m3 = avr = "skipped"
        m3_over = avr_over = False
        callbacks = 2 if kind.started else 1
        name = kind.mnemonic.lower() + ("-variables" if kind.variables else "")
        lines: list[str] = []
        if have_arm:
            images = {n: build(ARM, build_dir, f"{name}-{n}-m3", program(kind, n))
                      for n in (options.calls, 0)}
            ran, ran_without = (m3_instructions(images[n]) for n in (options.calls, 0))
            cost = (ran.total() - ran_without.total()) / options.calls
            m3, m3_over = f"{cost:.1f}", cost > kind.m3_goal
            if options.by_line:
                per_call = {address: (ran[address] - ran_without[address]) / options.calls
                            for address in ran.keys() | ran_without.keys()}
                lines = by_line(images[options.calls], per_call)
        if have_avr:
            with_calls, without = (avr_cycles(build(AVR, build_dir, f"{name}-{n}-avr",
                                                    program(kind, n)), callbacks * n)
                                   for n in (options.calls, 0))
            cost = (with_calls - without) / options.calls
            avr, avr_over = f"{cost:.1f}", kind.mnemonic == "KYC" and cost > GOAL_AVR_KYC
        avr_goal = str(GOAL_AVR_KYC) if kind.mnemonic == "KYC" else "-"
        print(f"{kind.label:<32} {m3:>22} {kind.m3_goal:>5}{' over' if m3_over else '     '}"
              f" {avr:>17} {avr_goal:>5}{' over' if avr_over else ''}")
        for line in lines:
            print(line)
        status |= m3_over or avr_over
    if not have_arm:
        print("Cortex-M3 skipped: no arm-none-eabi-gcc or qemu-system-arm (vm/c/install-tools)")
    if not have_avr:
        print("ATmega328P skipped: no avr-gcc or simavr (vm/c/install-tools)")
    return int(status)


if __name__ == "__main__":
    sys.exit(main())
