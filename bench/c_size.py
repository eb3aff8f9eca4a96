"""Flash, RAM and stack of the C VM and its loader and verifier (vm/c/) on the firmware
targets, from the objects `make -C vm/c cross` builds at -Os, against the goals of issue
13 (VM and verifier at most 4 KB of flash on Cortex-M3, no static RAM, a state struct of
at most 128 bytes, a stack of at most 256 bytes) and its anchors (EmbedVM ~3 KB with no
verifier, Microvium 7.3 KB on Cortex-M0).

Flash is text, rodata, initialized data and, on AVR, what is kept in program memory
(.progmem: the calls' descriptors, switch tables); static RAM is data and bss, and
rodata on AVR, whose start-up copies it to RAM: the VM must have none (on AVR it is
built with -fno-tree-switch-conversion, which would make lookup tables of its
switches). The state
struct (rl1_vm) is read from the size of test/probe.c's symbol. Stack: from gcc's
-fstack-usage, for each public entry the sum of its frame and every helper's it may call
(nothing recurses, and each helper appears at most once on a chain), a bound that leaves
out return addresses and the hardware callbacks, which are the firmware's; the emulated
targets (make -C vm/c targets) measure the high-water mark of a real run.

What the VM needs from outside: the symbols a bare link of its two objects leaves
undefined (`ld -r`, then `nm -u`). It calls no C library function; gcc's switch tables
call libgcc's helpers on Cortex-M0 at -Os and on AVR, which every gcc link includes
(after -nostdlib, add -lgcc). NEEDS is that set for each target, as vm/c/README.md
states it (tests/c/test_c_bare_link.py holds the two equal).

    python3 bench/c_size.py [BUILD-FOLDER]      (default vm/c/build, made first)

Sizes do not depend on the machine's load, so `make -C vm/c test` runs this as a check:
exit status 1 when a goal is missed (static RAM anywhere, an undefined symbol other than
NEEDS, or on Cortex-M3 more flash, struct or stack than the goals allow).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

# name, binutils prefix, object suffix, whether .rodata costs RAM (avr-gcc copies it there)
TARGETS = (("Cortex-M0", "arm-none-eabi-", "cortex-m0", False),
           ("Cortex-M3", "arm-none-eabi-", "cortex-m3", False),
           ("ATmega328P", "avr-", "atmega328p", True))
OBJECTS = ("rl1vm", "rl1vm_load")  # the VM, the loader and verifier
# Each public entry and the helpers it may call, by object (rl1_arg_in_range is for
# embedders: neither calls it, each checks a range with rl1vm.h's rl1_in_range).
Chain = dict[str, tuple[str, ...]]
LOAD_CHAIN: Chain = {"rl1vm_load": ("rl1_load", "leb128", "starts_instruction",
                                    "rl1_op_length", "check_")}
STEP_CHAIN: Chain = {"rl1vm": ("rl1_step", "take_event", "fault", "take_reading", "shifted",
                               "resume", "run", "ended"),
                     "rl1vm_load": ("rl1_op_length",)}
GOALS = {"flash": 4096, "struct": 128, "stack": 256}
# What a bare link of the VM and verifier leaves undefined, by target: libgcc's helpers
# for switch tables (Thumb-1 has no table branch instruction; AVR jumps through flash).
NEEDS: dict[str, frozenset[str]] = {
    "Cortex-M0": frozenset({"__gnu_thumb1_case_shi", "__gnu_thumb1_case_uhi"}),
    "Cortex-M3": frozenset(),
    "ATmega328P": frozenset({"__tablejump2__"}),
}


def sizes(tool: str, path: Path, rodata_in_ram: bool) -> tuple[int, int]:
    """Flash and static RAM of an object, from its sections (binutils' size -A)."""
    output = subprocess.run([tool, "-A", str(path)], check=True, capture_output=True,
                            text=True).stdout
    flash = ram = 0
    for line in output.splitlines():
        fields = line.split()
        if len(fields) < 2 or not fields[0].startswith(".") or not fields[1].isdigit():
            continue
        name, size = fields[0], int(fields[1])
        if name.startswith((".data", ".bss")) or (rodata_in_ram and name.startswith(".rodata")):
            ram += size
        if name.startswith((".text", ".rodata", ".data", ".progmem")):
            flash += size
    return flash, ram


def frames(path: Path) -> dict[str, int]:
    """Each function's frame from a -fstack-usage file (gcc may add .part.0 suffixes)."""
    found = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        where, size, _kind = line.split("\t")
        found[where.rsplit(":", 1)[1].split(".")[0]] = int(size)
    return found


def stack_bound(build: Path, suffix: str, chain: Chain) -> int:
    total = 0
    for object_name, names in chain.items():
        for function, size in frames(build / f"{object_name}-{suffix}.su").items():
            if function.startswith(names):
                total += size
    return total


def struct_size(tool: str, path: Path) -> int:
    output = subprocess.run([tool, "-S", str(path)], check=True, capture_output=True,
                            text=True).stdout
    for line in output.splitlines():
        fields = line.split()
        if fields[-1] == "rl1_vm_size_probe":
            return int(fields[1], 16)
    raise ValueError(f"no rl1_vm_size_probe in {path}")


def undefined_symbols(prefix: str, paths: list[Path], linked: Path) -> frozenset[str]:
    """What the objects at `paths`, linked together alone (`ld -r`: no start-up code,
    no library), still need from outside."""
    subprocess.run([prefix + "ld", "-r", "-o", str(linked), *map(str, paths)], check=True)
    output = subprocess.run([prefix + "nm", "-u", str(linked)], check=True,
                            capture_output=True, text=True).stdout
    return frozenset(line.split()[-1] for line in output.splitlines() if line.strip())


def main() -> int:
    vm_c = Path(__file__).parent.parent / "vm" / "c"
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("build", type=Path, nargs="?",
                        help="a folder of cross-built objects (default: vm/c/build, made first)")
    build = parser.parse_args().build
    if build is None:  # the default folder is brought up to date first: its objects may be stale
        build = vm_c / "build"
        subprocess.run(["make", "-s", "-C", str(vm_c), "cross"], check=False)
    print("-Os          flash: VM + verifier = total   static RAM   rl1_vm   "
          "stack bound: rl1_load, rl1_step")
    status = 0
    for name, prefix, suffix, rodata_in_ram in TARGETS:
        tool = prefix + "size"
        paths = [build / f"{object_name}-{suffix}.o" for object_name in OBJECTS]
        if shutil.which(tool) is None or not all(path.exists() for path in paths):
            print(f"{name:<12} skipped: no {tool} or no objects in {build} (make cross)")
            continue
        (vm_flash, vm_ram), (load_flash, load_ram) = (sizes(tool, path, rodata_in_ram)
                                                     for path in paths)
        struct = struct_size(prefix + "nm", build / f"probe-{suffix}.o")
        load_stack = stack_bound(build, suffix, LOAD_CHAIN)
        step_stack = stack_bound(build, suffix, STEP_CHAIN)
        needs = undefined_symbols(prefix, paths, build / f"bare-{suffix}.o")
        total = vm_flash + load_flash
        print(f"{name:<12} {vm_flash:>6} + {load_flash:>6} = {total:>5} bytes"
              f"   {vm_ram + load_ram:>6} bytes   {struct:>3} bytes   "
              f"{load_stack:>4}, {step_stack:>4} bytes")
        print(f"{'':<12} needs from outside (nm -u of a bare link): "
              f"{' '.join(sorted(needs)) or 'nothing'}")
        if vm_ram + load_ram:
            print(f"  {name}: the VM must have no static data")
            status = 1
        if needs != NEEDS[name]:
            print(f"  {name}: a bare link needs {' '.join(sorted(needs)) or 'nothing'}, "
                  f"where vm/c/README.md says {' '.join(sorted(NEEDS[name])) or 'nothing'}:"
                  f" remove the new call, or say it in the README and in NEEDS here")
            status = 1
        if name == "Cortex-M3":
            for goal, value in (("flash", total), ("struct", struct),
                                ("stack", max(load_stack, step_stack))):
                if value > GOALS[goal]:
                    print(f"  {name}: {goal} {value} bytes is over the goal of "
                          f"{GOALS[goal]} bytes")
                    status = 1
    print(f"goals (Cortex-M3): flash <= {GOALS['flash']}, no static RAM, rl1_vm <= "
          f"{GOALS['struct']} bytes (its 53 variables alone take 106), stack <= "
          f"{GOALS['stack']}")
    return status


if __name__ == "__main__":
    sys.exit(main())
