"""Flash and RAM of the C loader and verifier (vm/c/rl1vm_load.c) on the firmware
targets, from the objects `make -C vm/c cross` builds at -Os, against the anchors of
issue 13 (EmbedVM ~3 KB with no verifier, Microvium 7.3 KB on Cortex-M0).

Flash is text, rodata and initialized data; static RAM is data and bss, and rodata on
AVR, whose start-up copies it to RAM: the loader must have none (on AVR it is built with
-fno-tree-switch-conversion, which would make lookup tables of its switches). Stack:
each function's frame from gcc's -fstack-usage; as nothing recurses and each helper
appears at most once on a chain of calls, a call to `rl1_load` needs at most its frame
plus every helper's (return addresses aside), a bound rather than a measured high-water
mark.

    python3 bench/c_size.py [BUILD-FOLDER]      (default vm/c/build)
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

# name, size tool, object, whether .rodata costs RAM (avr-gcc's start-up copies it there)
TARGETS = (("Cortex-M0", "arm-none-eabi-size", "rl1vm_load-cortex-m0.o", False),
           ("Cortex-M3", "arm-none-eabi-size", "rl1vm_load-cortex-m3.o", False),
           ("ATmega328P", "avr-size", "rl1vm_load-atmega328p.o", True))


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
        if name.startswith((".text", ".rodata", ".data")):
            flash += size
    return flash, ram


PUBLIC = ("rl1_load", "rl1_line_at")


def stack_bound(path: Path) -> int:
    """rl1_load's frame plus every helper's (not the other public function's)."""
    frames = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        where, size, _kind = line.split("\t")
        frames[where.rsplit(":", 1)[1]] = int(size)
    return sum(size for name, size in frames.items() if name not in PUBLIC[1:])


def main() -> int:
    build = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent.parent / \
        "vm" / "c" / "build"
    print("loader + verifier, -Os   flash                static RAM             stack bound")
    status = 0
    for name, tool, object_name, rodata_in_ram in TARGETS:
        path = build / object_name
        if shutil.which(tool) is None or not path.exists():
            print(f"{name:<26} skipped: no {tool} or no {path}")
            continue
        flash, ram = sizes(tool, path, rodata_in_ram)
        stack = stack_bound(path.with_suffix(".su"))
        print(f"{name:<24} {flash:>8} bytes {ram:>18} bytes {stack:>8} bytes")
        if ram:
            print(f"  {name}: the loader must have no static data")
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
