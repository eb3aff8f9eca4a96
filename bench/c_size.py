"""Flash and RAM of the C loader and verifier (vm/c/rl1vm_load.c) on the firmware
targets, from the objects `make -C vm/c cross` builds at -Os, against the anchors of
issue 13 (EmbedVM ~3 KB with no verifier, Microvium 7.3 KB on Cortex-M0).

Flash is text + rodata (the size tools count rodata in text), static RAM data + bss:
the loader must have none. Stack: each function's frame from gcc's -fstack-usage; as
nothing recurses and each helper appears at most once on a chain of calls, a call to
`rl1_load` needs at most its frame plus every helper's (return addresses aside), a
bound rather than a measured high-water mark.

    python3 bench/c_size.py [BUILD-FOLDER]      (default vm/c/build)
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

TARGETS = (("Cortex-M0", "arm-none-eabi-size", "rl1vm_load-cortex-m0.o"),
           ("Cortex-M3", "arm-none-eabi-size", "rl1vm_load-cortex-m3.o"),
           ("ATmega328P", "avr-size", "rl1vm_load-atmega328p.o"))


def sizes(tool: str, path: Path) -> tuple[int, int, int]:
    """text, data, bss of an object, from the Berkeley format of binutils' size."""
    output = subprocess.run([tool, "-B", str(path)], check=True, capture_output=True,
                            text=True).stdout
    text, data, bss = (int(field) for field in output.splitlines()[1].split()[:3])
    return text, data, bss


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
    print("loader + verifier, -Os   flash (text+rodata)  static RAM (data+bss)  stack bound")
    status = 0
    for name, tool, object_name in TARGETS:
        path = build / object_name
        if shutil.which(tool) is None or not path.exists():
            print(f"{name:<26} skipped: no {tool} or no {path}")
            continue
        text, data, bss = sizes(tool, path)
        stack = stack_bound(path.with_suffix(".su"))
        print(f"{name:<24} {text:>8} bytes {data + bss:>18} bytes {stack:>8} bytes")
        if data + bss:
            print(f"  {name}: the loader must have no static data")
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
