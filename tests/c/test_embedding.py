"""vm/c/README.md's embedding code, as it is written: its C blocks are one firmware's
main.c, which builds with a fake vehicle (vm/c/test/embed/) on the host and, by the
README's AVR recipe run line by line, for the ATmega328P, where the program is read from
flash (rl1c --emit c --progmem) and Listing 1 runs under simavr as on the host. And the
VM from C++: a .cpp file includes rl1vm.h and links with the C objects."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from support import ROOT, SAMPLE

README = (ROOT / "vm" / "c" / "README.md").read_text(encoding="utf-8")
EMBED = ROOT / "vm" / "c" / "test" / "embed"
BIN = Path(sys.executable).parent  # rl1c
STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
CC = shutil.which("gcc") or shutil.which("cc")

needs_cc = pytest.mark.skipif(CC is None, reason="no C compiler (gcc or cc)")
needs_avr = pytest.mark.skipif(not (shutil.which("avr-gcc") and shutil.which("simavr")),
                               reason="no avr-gcc or simavr (vm/c/install-tools)")

# What the fake vehicle is told, in order, as Listing 1 runs on it: every image it
# takes is bright and low in the picture, so each loop is left at once.
LISTING_1_COMMANDS = [
    "idle", "start 79", "start 82 90", "start 81", "SCN 0", "TRC 3", "MOV 3 3",
    "start 78", "MOV 0 0", "TRC 0", "SCN 4", "start 78", "SCN 3", "start 78",
    "start 80", "SCN 2", "start 83 205",
    *["start 78", "start 83 205"] * 5,
    "start 71 -450", "MOV 1 1", "start 78", "MOV 0 0", "brake", "start 81", "SCN 0",
    "start 70 75", "TRC 0", "MOV 1 1", "start 78", "MOV 0 0", "start 69 75", "TRC 3",
    "start 67 1 1 50", "MOV 3 3", "MOV 0 0", "FRE",
]


def embedding_section() -> str:
    return README[README.index("## Embedding it"):README.index("## Memory")]


def readme_main_c() -> str:
    """The README's C blocks, one after the other."""
    return "\n".join(re.findall(r"```c\n(.*?)```", embedding_section(), re.S))


def readme_avr_recipe() -> list[str]:
    """The commands of the README's AVR recipe, each continued line joined."""
    blocks: list[str] = re.findall(r"```sh\n(.*?)```", embedding_section(), re.S)
    assert len(blocks) == 1, "the README's embedding section has one shell block"
    return blocks[0].replace("\\\n", " ").splitlines()


def workspace(tmp_path: Path) -> Path:
    """A folder laid out as the README's commands expect: the repository's vm/ and
    spec/, Listing 1 as line.rob, main.c from the README, the fake vehicle."""
    for folder in ("vm", "spec"):
        (tmp_path / folder).symlink_to(ROOT / folder)
    shutil.copy(SAMPLE, tmp_path / "line.rob")
    (tmp_path / "main.c").write_text(readme_main_c(), encoding="utf-8")
    for name in ("vehicle.c", "vehicle.h"):
        shutil.copy(EMBED / name, tmp_path / name)
    return tmp_path


def run(command: str | list[str], where: Path) -> str:
    """Runs a command (a shell line, or arguments) in `where` with rl1c on the PATH;
    its output, or the test fails with what it said."""
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    done = subprocess.run(command, cwd=where, env=env, shell=isinstance(command, str),
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, f"{command}\n{done.stdout}\n{done.stderr}"
    return done.stdout


def uart_lines(elf: Path) -> list[str]:
    """What the firmware sends on USART0 under simavr, line by line."""
    done = subprocess.run(["simavr", "-m", "atmega328p", "-f", "16000000", str(elf)],
                          capture_output=True, text=True, timeout=300)
    text = re.sub(r"\x1b\[[0-9;]*m", "", done.stdout + done.stderr)
    # simavr ends each line the USART sent with a dot of its own.
    return [line[:-1] for line in text.splitlines()
            if line.endswith(".") and not line.startswith("Loaded")]


def host_run(folder: Path, program: str) -> list[str]:
    assert CC is not None
    run(["rl1c", "compile", "line.rob", "--emit", "c", "--progmem", "--c-name",
         "program_ilc", "-o", program], folder)
    run([CC, *STRICT, "-Ivm/c", "-Ispec", "-o", "firmware", "main.c", "vehicle.c", program,
         "vm/c/rl1vm.c", "vm/c/rl1vm_load.c"], folder)
    return run([str(folder / "firmware")], folder).splitlines()


@needs_cc
def test_the_readme_code_builds_as_written_and_runs_listing_1(tmp_path: Path) -> None:
    lines = host_run(workspace(tmp_path), "program.c")
    assert lines[:-1] == LISTING_1_COMMANDS
    assert re.fullmatch(r"ended after \d+ instructions", lines[-1])


@needs_cc
@needs_avr
def test_the_readme_avr_recipe_reads_the_program_from_flash(tmp_path: Path) -> None:
    folder = workspace(tmp_path)
    for command in readme_avr_recipe():
        run(command, folder)
    symbols = run(["avr-objdump", "-t", "firmware.elf"], folder)
    array = next(line for line in symbols.splitlines() if line.endswith(" program_ilc"))
    assert ".text" in array.split()  # in flash (PROGMEM), not copied to .data
    on_avr = uart_lines(folder / "firmware.elf")
    assert on_avr == host_run(folder, "program_host.c")
    assert on_avr[:-1] == LISTING_1_COMMANDS


@needs_cc
@needs_avr
def test_without_progmem_the_avr_loader_refuses_the_file_at_its_magic(tmp_path: Path) -> None:
    """What --progmem fixes: read with pgm_read_byte, an array in RAM is read at a flash
    address, so the loader sees no magic (RL1_BAD_MAGIC, 2, at offset 0)."""
    folder = workspace(tmp_path)
    compile_line, build_line = readme_avr_recipe()
    run(compile_line.replace(" --progmem", ""), folder)
    run(build_line, folder)
    assert uart_lines(folder / "firmware.elf") == ["refused 2 0"]


@needs_cc
@pytest.mark.skipif(shutil.which("g++") is None, reason="no C++ compiler (g++)")
def test_a_cplusplus_file_links_with_the_c_vm_and_runs_a_program(tmp_path: Path) -> None:
    assert CC is not None
    (tmp_path / "small.rob").write_text("A=5; (MOV A,2)\nB=A<2; C=(INP 3)+1\n(MOV 0,-1)\n"
                                        "(END)\n", encoding="ascii")
    run(["rl1c", "compile", "small.rob", "--emit", "c", "--c-name", "program_ilc", "-o",
         "program.c"], tmp_path)
    include = ["-I", str(ROOT / "vm" / "c"), "-I", str(ROOT / "spec")]
    for source in ("program.c", ROOT / "vm" / "c" / "rl1vm.c",
                   ROOT / "vm" / "c" / "rl1vm_load.c"):
        run([CC, *STRICT, *include, "-c", str(source)], tmp_path)
    run(["g++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-pedantic", *include, "-c",
         str(EMBED / "cplusplus.cpp"), "-o", "cplusplus.o"], tmp_path)
    run(["g++", "-o", "embedded", "cplusplus.o", "program.o", "rl1vm.o", "rl1vm_load.o"],
        tmp_path)
    assert run([str(tmp_path / "embedded")], tmp_path) == \
        "state 2 fault 0, 3 calls, MOV 0 -1, A=5 B=20 C=31\n"
