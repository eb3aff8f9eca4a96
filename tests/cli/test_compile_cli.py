"""`rl1c FILE.rob -o FILE.ilc`: what is written, what is refused, and that a refused or
failed compilation never leaves a file behind or damages one."""

import os
import shutil
from pathlib import Path

import pytest
from intelhex import IntelHex
from support import SAMPLE
from support.cli import rl1c

from rl1.compiler.backend.firmware import c_source
from rl1.compiler.backend.ir_text import format_program
from rl1.compiler.backend.lower import lower
from rl1.compiler.backend.optimize import optimize
from rl1.compiler.files import write_atomically
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.ils.asm import assemble
from rl1.vm import ilc
from rl1.vm.defaults import DEFAULT_LEVEL
from rl1.vm.verifier import verify

BROKEN = "A=1\nB=(MOV 1\nC=2\n"


@pytest.fixture
def sample(tmp_path: Path) -> Path:
    return Path(shutil.copy(SAMPLE, tmp_path / "sample.rob"))


def test_compiles_to_an_ilc_beside_the_source_that_verifies(sample: Path) -> None:
    result = rl1c(str(sample))
    assert result.exit_code == 0, result.stderr
    assert result.stdout == ""
    image = verify((sample.parent / "sample.ilc").read_bytes()).image
    assert image.debug is not None and image.debug.source_name == "sample.rob"
    assert set(image.handlers) == {96, 99}


def test_the_verb_compile_may_be_left_out(sample: Path, tmp_path: Path) -> None:
    assert rl1c("compile", str(sample), "-o", str(tmp_path / "verb.ilc")).exit_code == 0
    assert rl1c(str(sample), "-o", str(tmp_path / "bare.ilc")).exit_code == 0
    assert (tmp_path / "verb.ilc").read_bytes() == (tmp_path / "bare.ilc").read_bytes()
    from_stdin = rl1c("-", "-o", str(tmp_path / "stdin.ilc"), stdin=SAMPLE.read_bytes())
    assert from_stdin.exit_code == 0
    verify((tmp_path / "stdin.ilc").read_bytes())


def test_output_path_and_o0(sample: Path, tmp_path: Path) -> None:
    result = rl1c(str(sample), "-O0", "-o", str(tmp_path / "out.ilc"))
    assert result.exit_code == 0, result.stderr
    verify((tmp_path / "out.ilc").read_bytes())
    assert not (tmp_path / "sample.ilc").exists()


def test_strip_drops_only_the_debug_section(sample: Path, tmp_path: Path) -> None:
    assert rl1c(str(sample), "-o", str(tmp_path / "full.ilc")).exit_code == 0
    assert rl1c(str(sample), "-s", "-o", str(tmp_path / "bare.ilc")).exit_code == 0
    full = ilc.decode((tmp_path / "full.ilc").read_bytes())
    bare = verify((tmp_path / "bare.ilc").read_bytes()).image
    assert bare.debug is None
    assert bare == ilc.strip_debug(full)
    assert (tmp_path / "bare.ilc").stat().st_size < (tmp_path / "full.ilc").stat().st_size


def test_emit_ir_prints_the_ir_or_writes_it_with_o(sample: Path, tmp_path: Path) -> None:
    lowered = lower(parse_program(SAMPLE.read_text(encoding="utf-8"))[0])
    expected = format_program(lowered)
    printed = rl1c(str(sample), "--emit", "ir", "-O0")
    assert printed.exit_code == 0 and printed.stdout == expected
    assert rl1c(str(sample), "--emit", "ir", "-O0", "-o", str(tmp_path / "s.ir")).exit_code == 0
    assert (tmp_path / "s.ir").read_text(encoding="utf-8") == expected
    assert not (tmp_path / "sample.ilc").exists()
    # Without -O, the IR after the default level's passes.
    optimized = rl1c(str(sample), "--emit", "ir")
    assert optimized.stdout == format_program(optimize(lowered, DEFAULT_LEVEL)) != expected


def test_emit_c_writes_the_ilc_bytes_as_a_c_array_beside_the_source(sample: Path) -> None:
    assert rl1c(str(sample), "-o", str(sample.parent / "ref.ilc")).exit_code == 0
    data = (sample.parent / "ref.ilc").read_bytes()
    result = rl1c(str(sample), "--emit", "c")
    assert result.exit_code == 0, result.stderr
    assert c_source(data, "sample_ilc", "sample.rob") \
        == (sample.parent / "sample.c").read_text(encoding="ascii")
    named = rl1c(str(sample), "--emit", "c", "--c-name", "route", "-o", "-")
    assert named.stdout == c_source(data, "route", "sample.rob")


def test_emit_c_from_standard_input_is_named_after_the_output(tmp_path: Path) -> None:
    result = rl1c("-", "--emit", "c", "-o", str(tmp_path / "line-2.c"), stdin=SAMPLE.read_bytes())
    assert result.exit_code == 0, result.stderr
    assert "const uint8_t line_2_ilc[" in (tmp_path / "line-2.c").read_text(encoding="ascii")
    unnamed = rl1c("-", "--emit", "c", "-o", "-", stdin=SAMPLE.read_bytes())
    assert "const uint8_t program_ilc[" in unnamed.stdout


@pytest.mark.parametrize("address, base", [(None, 0), ("0x08004000", 0x08004000),
                                           ("4096", 4096)])
def test_emit_ihex_places_the_ilc_bytes_at_the_base_address(
    sample: Path, address: str | None, base: int,
) -> None:
    assert rl1c(str(sample), "-o", str(sample.parent / "ref.ilc")).exit_code == 0
    data = (sample.parent / "ref.ilc").read_bytes()
    result = rl1c(str(sample), "--emit", "ihex",
                  *(["--base-address", address] if address is not None else []))
    assert result.exit_code == 0, result.stderr
    hex_file = IntelHex()
    hex_file.loadhex(str(sample.parent / "sample.hex"))
    assert (hex_file.minaddr(), hex_file.maxaddr()) == (base, base + len(data) - 1)
    assert hex_file.tobinstr(start=base, size=len(data)) == data


def test_emit_ils_is_the_text_that_assembles_to_the_same_ilc(sample: Path) -> None:
    assert rl1c(str(sample), "-o", str(sample.parent / "ref.ilc")).exit_code == 0
    result = rl1c(str(sample), "--emit", "ils")
    assert result.exit_code == 0, result.stderr
    text = (sample.parent / "sample.ils").read_text(encoding="utf-8")
    assert ";    3 | (SCN 0); (TRC 3); (MOV 3,3)" in text  # the source lines, interleaved
    assert assemble(text) == (sample.parent / "ref.ilc").read_bytes()
    stripped = rl1c(str(sample), "--emit", "ils", "-s", "-o", "-")
    assert ".source" not in stripped.stdout
    assert assemble(stripped.stdout) == ilc.encode(ilc.strip_debug(
        ilc.decode((sample.parent / "ref.ilc").read_bytes())))


def test_standard_input_and_output(tmp_path: Path) -> None:
    result = rl1c("-", "-o", "-", stdin=SAMPLE.read_bytes())
    assert result.exit_code == 0, result.stderr
    image = verify(result.stdout_bytes).image
    assert image.debug is not None and image.debug.source_name == "<stdin>"
    unnamed = rl1c("-", stdin=SAMPLE.read_bytes())
    assert unnamed.exit_code == 2 and "give -o FILE.ilc" in unnamed.stderr
    unnamed_c = rl1c("-", "--emit", "c", stdin=SAMPLE.read_bytes())
    assert unnamed_c.exit_code == 2 and "give -o FILE.c" in unnamed_c.stderr


@pytest.mark.parametrize("args, message", [
    (["-O3"], "`-O3`: the levels are -O0, -O1, -O2"),
    (["-O", "s"], "the levels are -O0, -O1, -O2"),
    (["--emit", "ir", "-s"], "no meaning with --emit ir"),
    (["--emit", "asm"], "argument --emit: invalid choice: 'asm'"),
    (["--c-name", "x"], "--c-name names the array of --emit c"),
    (["--emit", "ihex", "--progmem"], "--progmem places the array of --emit c"),
    (["--emit", "c", "--c-name", "2x"], "argument --c-name: `2x` is not a C identifier"),
    (["--emit", "c", "--c-name", "int"], "`int` is a C keyword"),
    (["--base-address", "0x100"], "--base-address places the bytes of --emit ihex"),
    (["--emit", "ihex", "--base-address", "0x1_0000_0000"], "expected an address from 0"),
    (["--emit", "ihex", "--base-address", "-1"], "expected an address from 0"),
    (["--emit", "ihex", "--base-address", "0xFFFFFF00"], "reach past 4 GiB"),
])
def test_bad_options_are_usage_errors_and_write_nothing(
    sample: Path, args: list[str], message: str,
) -> None:
    result = rl1c(str(sample), *args)
    assert result.exit_code == 2
    assert message in result.stderr
    assert sorted(os.listdir(sample.parent)) == ["sample.rob"]


def test_errors_refuse_to_write_and_are_printed_as_check_prints_them(tmp_path: Path) -> None:
    source = tmp_path / "broken.rob"
    source.write_text(BROKEN, encoding="utf-8")
    output = tmp_path / "broken.ilc"
    output.write_bytes(b"an older build")
    result = rl1c(str(source), "--color", "never")
    assert result.exit_code == 1
    assert result.stdout == ""
    checked = rl1c("check", str(source), "--color", "never")
    assert checked.exit_code == 1
    # The same diagnostics; each command closes them with its own one summary line.
    assert result.stderr == checked.stdout.replace(
        "1 file checked: 1 error, 0 warnings\n",
        f"error: could not compile `{source}`: 1 error emitted\n")
    assert "error[E0101]" in result.stderr
    assert output.read_bytes() == b"an older build"
    assert sorted(os.listdir(tmp_path)) == ["broken.ilc", "broken.rob"]


def test_warnings_are_printed_and_do_not_block(tmp_path: Path) -> None:
    source = tmp_path / "warned.rob"
    source.write_text("A=1\nB=s\n(END)\n", encoding="utf-8")  # W0401: `s` may be unset
    result = rl1c(str(source), "--color", "never")
    assert result.exit_code == 0
    assert "warning[W0401]: `s` is read here" in result.stderr
    assert "warned.rob:2:3" in result.stderr
    verify((tmp_path / "warned.ilc").read_bytes())


def test_code_too_large_is_refused_with_e0190(tmp_path: Path) -> None:
    # A=B+1 is 7 bytes (LDV, ADDI, STV): 9363 of them pass 65535 bytes at line 9363
    # (unoptimized: -O1 keeps only the last, the others being dead stores).
    source = tmp_path / "huge.rob"
    source.write_text("A=B+1\n" * 9363, encoding="utf-8")
    assert rl1c(str(source), "-o", str(tmp_path / "small.ilc")).exit_code == 0
    (tmp_path / "small.ilc").unlink()
    result = rl1c(str(source), "-O0", "--color", "never")
    assert result.exit_code == 1
    assert "error[E0190]" in result.stderr and "huge.rob:9363:1" in result.stderr
    assert sorted(os.listdir(tmp_path)) == ["huge.rob"]


def test_code_past_line_65535_needs_strip(tmp_path: Path) -> None:
    source = tmp_path / "long.rob"
    source.write_text("\n" * 70000 + "(MOV 1,1)\n", encoding="utf-8")
    refused = rl1c(str(source), "--color", "never")
    assert refused.exit_code == 1
    assert "error[E0191]" in refused.stderr and "long.rob:70001:1" in refused.stderr
    assert sorted(os.listdir(tmp_path)) == ["long.rob"]
    stripped = rl1c(str(source), "-s")
    assert stripped.exit_code == 0, stripped.stderr
    verify((tmp_path / "long.ilc").read_bytes())


def test_unreadable_source_is_exit_2(tmp_path: Path) -> None:
    missing = rl1c(str(tmp_path / "missing.rob"))
    assert missing.exit_code == 2 and "error[E0100]" in missing.stderr
    directory = rl1c(str(tmp_path))
    assert directory.exit_code == 2 and "is a directory" in directory.stderr
    assert os.listdir(tmp_path) == []


def test_unwritable_output_is_exit_2_with_the_reason(sample: Path, tmp_path: Path) -> None:
    result = rl1c(str(sample), "-o", str(tmp_path / "no" / "such" / "dir.ilc"))
    assert result.exit_code == 2
    assert (f"error[E0100]: cannot write the output file `{tmp_path / 'no' / 'such' / 'dir.ilc'}`"
            ": no such file or directory\n") in result.stderr
    assert "= help: check that its folder exists and is writable" in result.stderr


def test_the_source_is_never_the_output(sample: Path) -> None:
    result = rl1c(str(sample), "-o", str(sample))
    assert result.exit_code == 2 and "is the source file itself" in result.stderr
    assert sample.read_bytes() == SAMPLE.read_bytes()


# Atomic writes ------------------------------------------------------------------------


def test_atomic_write_replaces_a_file_and_keeps_its_permissions(tmp_path: Path) -> None:
    target = tmp_path / "out.ilc"
    target.write_bytes(b"old")
    target.chmod(0o640)
    write_atomically(target, b"new")
    assert target.read_bytes() == b"new"
    assert target.stat().st_mode & 0o777 == 0o640
    assert os.listdir(tmp_path) == ["out.ilc"]


def test_atomic_write_gives_a_new_file_the_usual_permissions(tmp_path: Path) -> None:
    umask = os.umask(0o022)
    try:
        write_atomically(tmp_path / "new.ilc", b"data")
    finally:
        os.umask(umask)
    assert (tmp_path / "new.ilc").stat().st_mode & 0o777 == 0o644


def test_failed_write_leaves_the_old_file_and_no_temporary(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    target = tmp_path / "out.ilc"
    target.write_bytes(b"old")

    def failing_replace(source: str, destination: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", failing_replace)
    with pytest.raises(OSError):
        write_atomically(target, b"new")
    assert target.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["out.ilc"]


def test_failed_write_through_the_cli_reports_and_leaves_nothing(
    sample: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    def failing_replace(source: str, destination: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", failing_replace)
    result = rl1c(str(sample))
    assert result.exit_code == 2
    assert "cannot write the output file" in result.stderr
    assert "no space left on device" in result.stderr
    assert sorted(os.listdir(sample.parent)) == ["sample.rob"]
