"""The .ilc bytes as a C99 array and as Intel HEX (`rl1c --emit c`, `--emit ihex`): the C
compiles without a warning and holds the same bytes (in AVR flash with --progmem), and an
independent Intel HEX reader (the intelhex package) reads back the same bytes at the same
addresses."""

from __future__ import annotations

import io
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from intelhex import IntelHex

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.backend.firmware import (
    ADDRESS_SPACE,
    c_name_for,
    c_name_problem,
    c_source,
    intel_hex,
)
from rl1.compiler.strategies import checked_programs

CC = shutil.which("cc")
needs_cc = pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")

PRINT_ARRAY = """\
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

extern const uint8_t {name}[];
extern const uint32_t {name}_size;

int main(void) {{
    return fwrite({name}, 1, {name}_size, stdout) == {name}_size ? 0 : 1;
}}
"""


def bytes_through_cc(c_text: str, name: str, directory: Path) -> bytes:
    """Compiles `c_text` as C99 with every warning an error, links it with a program
    that writes the array NAME[NAME_size] to standard output, and runs that."""
    assert CC is not None
    (directory / "program.c").write_text(c_text, encoding="ascii")
    (directory / "main.c").write_text(PRINT_ARRAY.format(name=name), encoding="ascii")
    for unit in ("program", "main"):
        subprocess.run([CC, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-c",
                        f"{unit}.c", "-o", f"{unit}.o"], cwd=directory, check=True,
                       capture_output=True)
    subprocess.run([CC, "program.o", "main.o", "-o", "print"], cwd=directory, check=True,
                   capture_output=True)
    return subprocess.run([str(directory / "print")], check=True,
                          capture_output=True).stdout


def ilc_of(source: str) -> bytes:
    compilation = compile_text(source, "prog.rob")
    assert compilation.output is not None, compilation.diagnostics
    return compilation.output


@needs_cc
@settings(max_examples=8, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(checked_programs(), st.booleans())
def test_the_c_array_compiles_and_holds_the_ilc_bytes(tmp_path: Path, source: str,
                                                     progmem: bool) -> None:
    data = ilc_of(source)
    assert bytes_through_cc(c_source(data, "prog_ilc", "prog.rob", progmem), "prog_ilc",
                            tmp_path) == data


@given(st.binary(max_size=300), st.sampled_from(["a", "sample_ilc", "x9"]), st.booleans())
def test_the_c_array_spells_every_byte_in_order(data: bytes, name: str, progmem: bool) -> None:
    text = c_source(data, name, "p.rob", progmem)
    placed = " PROGMEM" if progmem else ""
    body = re.search(r"const uint8_t " + name + r"\[(\d+)\]" + placed + r" = \{\n(.*?)\};\n",
                     text, re.S)
    assert body is not None and int(body.group(1)) == len(data)
    assert bytes(int(byte, 16) for byte in re.findall(r"0x([0-9a-f]{2})", body.group(2))) == data
    assert f"const uint32_t {name}_size = {len(data)}u;\n" in text


AVR_GCC = shutil.which("avr-gcc")


@pytest.mark.skipif(AVR_GCC is None, reason="no avr-gcc (vm/c/install-tools installs it)")
@pytest.mark.parametrize("progmem, section", [(True, ".progmem.data"), (False, ".rodata")])
def test_progmem_puts_the_array_in_avr_flash(tmp_path: Path, progmem: bool,
                                             section: str) -> None:
    """avr-gcc's start-up copies .rodata to RAM; .progmem.data stays in flash. The size
    is an ordinary constant either way (read with a plain load)."""
    assert AVR_GCC is not None
    (tmp_path / "program.c").write_text(c_source(bytes(range(40)), "prog_ilc", "p.rob",
                                                 progmem), encoding="ascii")
    subprocess.run([AVR_GCC, "-mmcu=atmega328p", "-Os", "-std=c99", "-Wall", "-Wextra",
                    "-Werror", "-pedantic", "-c", "program.c", "-o", "program.o"],
                   cwd=tmp_path, check=True, capture_output=True)
    symbols = subprocess.run(["avr-objdump", "-t", "program.o"], cwd=tmp_path, check=True,
                             capture_output=True, text=True).stdout
    array = next(line for line in symbols.splitlines() if line.endswith(" prog_ilc"))
    size = next(line for line in symbols.splitlines() if line.endswith(" prog_ilc_size"))
    assert section in array.split() and ".rodata" in size.split()


@pytest.mark.parametrize("stem, name", [
    ("sample", "sample_ilc"), ("line-follow 2", "line_follow_2_ilc"),
    ("1st", "rl1_1st_ilc"), ("_hidden", "hidden_ilc"), ("日本", "program_ilc"),
    ("", "program_ilc"),
])
def test_the_default_name_is_a_c_identifier_from_the_file_name(stem: str, name: str) -> None:
    assert c_name_for(stem) == name
    assert c_name_problem(name) is None


@pytest.mark.parametrize("name, problem", [
    ("2fast", "not a C identifier"), ("a-b", "not a C identifier"), ("", "not a C identifier"),
    ("static", "a C keyword"), ("_ilc", "C reserves"), ("__x", "C reserves"),
])
def test_names_c_cannot_take_are_refused(name: str, problem: str) -> None:
    found = c_name_problem(name)
    assert found is not None and problem in found


def read_hex(text: str) -> IntelHex:
    hex_file = IntelHex()
    hex_file.loadhex(io.StringIO(text))
    return hex_file


@given(st.binary(min_size=1, max_size=200),
       st.one_of(st.integers(0, 0xFFFF), st.integers(0xFF00, 0x30000),
                 st.integers(0, ADDRESS_SPACE - 200)))
def test_intel_hex_reads_back_as_the_same_bytes_at_the_base_address(data: bytes,
                                                                      base: int) -> None:
    hex_file = read_hex(intel_hex(data, base))
    assert (hex_file.minaddr(), hex_file.maxaddr()) == (base, base + len(data) - 1)
    assert hex_file.tobinstr(start=base, size=len(data)) == data


@settings(deadline=None)
@given(checked_programs(), st.integers(0, ADDRESS_SPACE - 0x10000))
def test_a_compiled_program_reads_back_from_intel_hex(source: str, base: int) -> None:
    data = ilc_of(source)
    assert read_hex(intel_hex(data, base)).tobinstr(start=base, size=len(data)) == data


def test_records_never_cross_a_64k_segment_and_the_file_ends_with_eof() -> None:
    text = intel_hex(bytes(range(40)), 0xFFF8)
    # Without the checksums, which the reader checks.
    assert [record[:-2] for record in text.splitlines()] == [
        ":08FFF800" + bytes(range(8)).hex().upper(),
        ":0200000400" + "01",
        ":10000000" + bytes(range(8, 24)).hex().upper(),
        ":10001000" + bytes(range(24, 40)).hex().upper(),
        ":00000001",
    ]
    assert read_hex(text).tobinstr(start=0xFFF8, size=40) == bytes(range(40))


def test_bytes_past_4_gib_are_refused() -> None:
    with pytest.raises(ValueError, match="past 4 GiB"):
        intel_hex(b"\x00\x01", ADDRESS_SPACE - 1)
