"""What the C VM needs from outside on each firmware target, as vm/c/README.md states it:
the objects `make -C vm/c cross` builds, linked alone (no start-up code, no library),
leave undefined exactly bench/c_size.py's NEEDS, which the README's table names; a
-nostdlib link succeeds with libgcc alone and fails without it naming those symbols;
and built with -fno-jump-tables they need nothing at all.

Each target is skipped when its cross compiler is missing (vm/c/install-tools)."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from support import ROOT

sys.path.insert(0, str(ROOT / "bench"))
import c_size

C_DIR = ROOT / "vm" / "c"
README = C_DIR / "README.md"
NEEDS_HEADING = "| target, gcc -Os | what a bare link of both files needs |"
# name as c_size.TARGETS has it, to its compiler and its -mcpu or -mmcu
COMPILERS = {"Cortex-M0": ("arm-none-eabi-gcc", "-mcpu=cortex-m0", "-mthumb"),
             "Cortex-M3": ("arm-none-eabi-gcc", "-mcpu=cortex-m3", "-mthumb"),
             "ATmega328P": ("avr-gcc", "-mmcu=atmega328p")}
TARGETS = {name: (prefix, suffix) for name, prefix, suffix, _ in c_size.TARGETS}


def cross_build(folder: Path, freestanding: str | None = None) -> Path:
    """The objects as `make -C vm/c cross` builds them (the Makefile's flags, with its
    FREESTANDING flags replaced when given)."""
    command = ["make", "--no-print-directory", "-C", str(C_DIR), "cross", f"BUILD={folder}"]
    if freestanding is not None:
        command.append(f"FREESTANDING={freestanding}")
    subprocess.run(command, check=True, capture_output=True, text=True)
    return folder


@pytest.fixture(scope="module")
def build(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return cross_build(tmp_path_factory.mktemp("cross"))


def objects(build: Path, name: str) -> list[Path]:
    compiler = COMPILERS[name][0]
    if shutil.which(compiler) is None:
        pytest.skip(f"no {compiler} on this machine: vm/c/install-tools installs it")
    _, suffix = TARGETS[name]
    return [build / f"{object_name}-{suffix}.o" for object_name in c_size.OBJECTS]


def documented_needs() -> dict[str, frozenset[str]]:
    """The README's table of what a bare link needs: from its heading to the blank line
    after it, a row per target with its symbols in backquotes, then why in brackets."""
    text = README.read_text(encoding="utf-8")
    table = text[text.index(NEEDS_HEADING):].split("\n\n", 1)[0]
    rows = re.findall(r"^\| ([\w-]+) \| (.*) \|$", table, flags=re.MULTILINE)
    return {name: frozenset(re.findall(r"`(\w+)`", needs.split(" (")[0]))
            for name, needs in rows}


def test_the_readme_states_what_bench_c_size_checks() -> None:
    assert documented_needs() == c_size.NEEDS


@pytest.mark.parametrize("name", list(COMPILERS))
def test_a_bare_link_needs_what_the_readme_says(build: Path, name: str) -> None:
    paths = objects(build, name)
    prefix, suffix = TARGETS[name]
    needs = c_size.undefined_symbols(prefix, paths, build / f"bare-{suffix}.o")
    assert needs == documented_needs()[name]
    assert "memset" not in needs  # issue 26: a struct's zeroing called it on Cortex-M0


@pytest.mark.parametrize("name", [name for name, needs in c_size.NEEDS.items() if needs])
def test_a_nostdlib_link_needs_libgcc_alone(build: Path, name: str, tmp_path: Path) -> None:
    paths = objects(build, name)
    compiler, *machine = COMPILERS[name]
    link = [compiler, *machine, "-nostdlib", "-Wl,--entry=rl1_step", "-o",
            str(tmp_path / "vm.elf"), *map(str, paths)]
    without = subprocess.run(link, capture_output=True, text=True)
    assert without.returncode != 0
    missing = set(re.findall(r"undefined reference to `(\w+)'", without.stderr))
    assert missing == c_size.NEEDS[name]
    subprocess.run([*link, "-lgcc"], check=True, capture_output=True, text=True)


def test_without_jump_tables_nothing_is_needed(tmp_path: Path) -> None:
    build = cross_build(tmp_path, "-ffreestanding -fno-builtin -fno-jump-tables")
    for name in COMPILERS:
        if shutil.which(COMPILERS[name][0]) is None:
            continue
        prefix, suffix = TARGETS[name]
        needs = c_size.undefined_symbols(prefix, objects(build, name),
                                         build / f"bare-{suffix}.o")
        assert needs == frozenset(), name
