"""The .ils text form: `dis` then `asm` gives back the same bytes, errors point at their
line and column, and the `rl1c dis` / `rl1c asm` commands."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import SAMPLE
from support.cli import rl1c
from support.ilc import images

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.ils.asm import AsmError, assemble
from rl1.compiler.ils.disasm import disassemble
from rl1.vm import ilc
from rl1.vm.language import Feature
from rl1.vm.verifier import verify

HAND_WRITTEN = """\
; a loop that counts A down from 5
.handler 96 loop
.source "count.rob"
.line 1
        LDI 5
        STV A
.line 3
loop:   DEC A
        JGT A, loop
        MOV A, -3        ; a variable and a constant argument
        MVI 3, 3, $10
        .line none
        ULTA
        ADDR
        END
"""


@settings(max_examples=100, deadline=None)
@given(images(), st.lists(st.text(alphabet=st.characters(exclude_categories=["Cs", "Cc"])),
                          max_size=30) | st.none())
def test_assembling_the_disassembly_gives_the_same_bytes(
    image: ilc.Image, source: list[str] | None,
) -> None:
    data = ilc.encode(image)
    text = disassemble(data, "x.ilc", source)
    assert assemble(text) == data


def test_optional_flags_survive_dis_and_asm_and_unknown_required_ones_are_refused() -> None:
    data = assemble(".flags $8100\nEND\n")
    assert ilc.read_header(data).flags == 0x8100
    text = disassemble(data, "x.ilc")
    assert ".flags $8100" in text.splitlines()
    assert assemble(text) == data
    with pytest.raises(AsmError) as refused:
        assemble("END\n.flags 1\n")
    (problem,) = refused.value.problems
    assert (problem.line, problem.column) == (2, 1)
    assert "unknown required flag bits 0x0001" in problem.message




@pytest.mark.parametrize("strip", [False, True])
def test_listing_1_compiled_survives_dis_and_asm(strip: bool) -> None:
    text = SAMPLE.read_text(encoding="utf-8")
    data = compile_text(text, "sample.rob", strip_debug=strip).output
    assert data is not None
    shown = disassemble(data, "sample.ilc", text.splitlines())
    assert assemble(shown) == data
    assert ("; 4 | :10 A=(IMG)-180; ?A<#10" in " ".join(shown.split())) != strip


def test_a_hand_written_program_assembles_to_what_it_says() -> None:
    program = verify(assemble(HAND_WRITTEN))
    names = [i.info.name for i in program.instructions]
    assert names == ["LDI", "STV", "DEC", "JGT", "MOV", "MVI", "ULTA", "ADDR", "END"]
    loop = program.instructions[2].offset
    assert program.instructions[3].operands == (0, loop)
    assert program.instructions[5].args[2].value == 16
    assert program.image.handlers == {96: loop}
    # Without .features, the features are what the calls need.
    assert program.image.features == {Feature.MOTION, Feature.ULTRASONIC}
    debug = program.image.debug
    assert debug is not None and debug.source_name == "count.rob"
    # `.line none` ends the map: the last three instructions have no entry.
    assert [line for _, line in debug.lines] == [1, 1, 3, 3, 3, 3]


def test_the_disassembly_shows_the_header_tables_offsets_and_source() -> None:
    data = assemble(HAND_WRITTEN)
    source = ["A=5", "' count down", ":10 A--; ?A>#10", "(MOV A,-3)"]
    text = disassemble(data, "count.ilc", source)
    assert f"CRC-32 0x{ilc.read_header(data).crc:08X}, {len(data)} bytes" in text
    assert ".features MOTION ULTRASONIC\n.handler 96 L0005\n.handler 97 none\n" in text
    # The source lines up to an instruction's line come before it, as comments.
    assert ";    2 | ' count down\n        ;    3 | :10 A--; ?A>#10\n        .line 3\n" \
        "L0005:\n  0005  DEC A\n  0007  JGT A, L0005\n" in text
    assert disassemble(data, "count.ilc").count(" | ") == 0


@pytest.mark.parametrize(("text", "line", "column", "message"), [
    ("LDI 40000", 1, 5, "constant 40000 is out of range -32768..32767"),
    ("LDI $10000", 1, 5, "out of range"),
    ("MOVB A, 128", 1, 9, "byte constant 128 is out of range -128..127"),
    ("TIMS 128", 1, 6, "byte constant 128 is out of range -128..127"),
    ("MOVS 0, 13", 1, 9, "MOVS argument r = 13 is out of range -12..12"),
    ("END\nFOO", 2, 1, "unknown instruction FOO"),
    ("LDV AB", 1, 5, "expected a variable (A-Z, a-z or @), found 'AB'"),
    ("MOV 1", 1, 1, "MOV takes 2 operands, found 1"),
    ("LDV A,", 1, 7, "expected an operand after ','"),
    ("END extra", 1, 5, "END takes 0 operands, found 1"),
    ("LDI 1 2", 1, 7, "unexpected '2' at the end of the line"),
    ("JMP nowhere", 1, 5, "unknown label nowhere"),
    ("x: END\nx: END", 2, 1, "label x is defined twice"),
    ("  0003 END", 1, 3, "this line says code offset 3, but its instruction assembles at 0"),
    (".line 3", 1, 1, ".line needs a .source"),
    ('.source "a"\n.line 3\nEND\n.line 2', 4, 1, "line 2 comes after line 3"),
    ('.source "a\\q"', 1, 11, "bad string"),
    ('.source "a', 1, 9, "a string without its closing quote"),
    (".features WARP", 1, 11, "unknown feature WARP"),
    (".features\n.features", 2, 1, ".features is given twice"),
    (".handler 95 none", 1, 10, "handler label 95 is out of range 96..99"),
    ("END\n.handler 96 5", 2, 13, "handler :96 at 5 is outside the 1-byte code"),
    (".bogus", 1, 1, "unknown directive .bogus"),
    ('.digest "00"', 1, 1, ".digest needs a .source"),
    ('.source "a"\n.digest "00"', 2, 9, "a source digest is 16 bytes"),
    ('.source "a"\n.digest "' + "0g" * 16 + '"', 2, 9, "32 hexadecimal digits"),
    ('.source "a"\n.digest "' + "00" * 16 + '"\n.digest "00"', 3, 1, "given twice"),
    ("LDI 1 # 2", 1, 7, "unexpected character '#'"),
    # Refusals of the verifier, reported at the operand that caused them.
    ("LDI 0\nJMP 1", 2, 5, "jump target 1 is in the middle of the instruction at 0"),
    ("MOV 0, 13", 1, 8, "MOV argument r = 13 is out of range -12..12"),
    (".features\nIMG", 2, 1, "IMG needs the device feature VISION"),
    ("LDI 0\nEND\n.handler 99 1", 3, 1, "handler :99 at code offset 1 is in the middle"),
])
def test_errors_say_where(text: str, line: int, column: int, message: str) -> None:
    with pytest.raises(AsmError) as caught:
        assemble(text)
    problem = caught.value.problems[0]
    assert (problem.line, problem.column) == (line, column)
    assert message in problem.message


def test_every_line_with_an_error_is_reported() -> None:
    with pytest.raises(AsmError) as caught:
        assemble("FOO\nLDI 5\nLDV 7\nBAR")
    assert [(p.line, p.column) for p in caught.value.problems] == [(1, 1), (3, 5), (4, 1)]


def test_check_false_assembles_a_file_the_verifier_refuses() -> None:
    data = assemble("MOV 13, 0", check=False)
    assert ilc.decode(data).code[2:4] == (13).to_bytes(2, "little")


# --- the commands --------------------------------------------------------------------

def test_dis_then_asm_on_the_command_line(tmp_path: Path) -> None:
    (tmp_path / "count.rob").write_text("A=5\n' count down\n:10 A--; ?A>#10\n")
    (tmp_path / "count.ilc").write_bytes(assemble(HAND_WRITTEN))
    shown = rl1c("dis", tmp_path / "count.ilc")
    assert shown.exit_code == 0
    # No digest (format 1.0): the file beside it could be any file, so it is not shown.
    assert " | " not in shown.stdout
    assert "no source digest (format 1.0)" in shown.stderr and "--source" in shown.stderr
    named = rl1c("dis", tmp_path / "count.ilc", "--source", tmp_path / "count.rob")
    assert ";    3 | :10 A--; ?A>#10" in named.stdout  # what the user names is shown
    assert "cannot be checked against the source compiled" in named.stderr
    (tmp_path / "count.ils").write_text(shown.stdout)
    built = rl1c("asm", tmp_path / "count.ils", "-o", tmp_path / "again.ilc")
    assert built.exit_code == 0
    assert (tmp_path / "again.ilc").read_bytes() == (tmp_path / "count.ilc").read_bytes()
    default = rl1c("asm", tmp_path / "count.ils")
    assert default.exit_code == 0  # FILE.ilc beside the .ils by default
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "again.ilc", "count.ilc", "count.ils", "count.rob"]  # no temporary file left


def test_asm_reports_errors_with_file_line_column_and_writes_nothing(tmp_path: Path) -> None:
    source = tmp_path / "bad.ils"
    source.write_text("LDI 5\nFOO\n")
    result = rl1c("asm", source, "-o", tmp_path / "bad.ilc")
    assert result.exit_code == 1
    assert f"{source}:2:1: error: unknown instruction FOO" in result.output
    assert not (tmp_path / "bad.ilc").exists()


def test_unreadable_files_exit_2(tmp_path: Path) -> None:
    assert rl1c("dis", tmp_path / "none.ilc").exit_code == 2
    assert rl1c("asm", tmp_path / "none.ils").exit_code == 2
    (tmp_path / "ok.ils").write_text("END\n")
    unwritable = rl1c("asm", tmp_path / "ok.ils", "-o", tmp_path / "no" / "dir.ilc")
    assert unwritable.exit_code == 2
    assert "cannot write" in unwritable.output


def test_dis_refuses_an_invalid_file_with_its_offset(tmp_path: Path) -> None:
    (tmp_path / "x.ilc").write_bytes(b"RLIX" + assemble("END")[4:])
    result = rl1c("dis", tmp_path / "x.ilc")
    assert result.exit_code == 1
    assert "is not valid: it does not start with `RLIC` (its first bytes are 52 4C 49 58)" \
        in result.output
    (tmp_path / "y.ilc").write_bytes(assemble("END")[:-1])
    cut = rl1c("dis", tmp_path / "y.ilc")
    assert cut.exit_code == 1 and "is not valid: byte " in cut.output


def test_dis_says_a_source_is_source_text_and_what_to_run(tmp_path: Path) -> None:
    # Issue 22: "it starts with b"' ob"", a Python bytes repr.
    source = tmp_path / "p.rob"
    source.write_text("' obstacle course\nA=1\n", encoding="utf-8")
    result = rl1c("dis", source)
    assert result.exit_code == 1
    assert result.stderr.startswith(f"error[E0100]: the intermediate code file `{source}` is "
                                    "not valid: it is RL/I source text, not compiled code\n")
    assert f"`rl1c compile {source} -o {tmp_path / 'p.ilc'}`" in result.stderr
    assert "b'" not in result.stderr and 'b"' not in result.stderr
    notes = tmp_path / "notes.txt"
    for data, detail in ((b"hi\n", "it is text, not compiled code"), (b"", "it is empty")):
        notes.write_bytes(data)  # too short for a header: still named for what it is
        other = rl1c("dis", notes)
        assert other.exit_code == 1 and f"is not valid: {detail}\n" in other.stderr


def _ilc_naming(tmp_path: Path, source_name: str, source: str | None = None) -> Path:
    """An .ilc file in `tmp_path` recording `source_name`, with the digest of `source`
    (None: no digest, format 1.0)."""
    target = tmp_path / "named.ilc"
    digest = "" if source is None else f'.digest "{ilc.source_digest(source).hex()}"\n'
    target.write_bytes(assemble(f".source {json.dumps(source_name)}\n{digest}"
                                ".line 1\nLDI 1\nEND\n"))
    return target


SECRET = "SECRET=1\n"


@pytest.mark.parametrize("name", ["/etc/passwd", "../secret.rob", "sub/../../secret.rob",
                                  "link.rob"])
def test_dis_shows_no_file_a_recorded_name_leads_to_without_its_digest(
        tmp_path: Path, name: str) -> None:
    # Issue 23: a cloned repository holding an .ilc and a link named as its source.
    (tmp_path / "secret.rob").write_text(SECRET, encoding="utf-8")
    folder = tmp_path / "build"
    (folder / "sub").mkdir(parents=True)
    (folder / "link.rob").symlink_to(tmp_path / "secret.rob")
    for digest_of in (None, "A=1\n"):  # none, or another file's
        shown = rl1c("dis", _ilc_naming(folder, name, digest_of))
        assert shown.exit_code == 0
        assert "SECRET" not in shown.stdout and "root:" not in shown.stdout
        assert "        .line 1" in shown.stdout and "--source" in shown.stderr
    assert "not a path from its folder" in shown.stderr if name.startswith("/") \
        else "is not the source" in shown.stderr


@pytest.mark.parametrize("name", ["../secret.rob", "sub/../../secret.rob", "link.rob"])
def test_dis_follows_a_relative_name_to_the_source_whose_digest_is_recorded(
        tmp_path: Path, name: str) -> None:
    (tmp_path / "secret.rob").write_text(SECRET, encoding="utf-8")
    folder = tmp_path / "build"
    (folder / "sub").mkdir(parents=True)
    (folder / "link.rob").symlink_to(tmp_path / "secret.rob")
    shown = rl1c("dis", _ilc_naming(folder, name, SECRET))
    assert (shown.exit_code, shown.stderr) == (0, "")
    assert ";    1 | SECRET=1" in shown.stdout


def test_dis_finds_the_source_in_the_layout_of_make_demo(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue 22: `rl1c examples/sample.rob -o build/sample.ilc` records
    `../examples/sample.rob`, which dis called outside its folder."""
    for folder in ("examples", "build"):
        (tmp_path / folder).mkdir()
    (tmp_path / "examples" / "sample.rob").write_bytes(SAMPLE.read_bytes())
    monkeypatch.chdir(tmp_path)
    assert rl1c("examples/sample.rob", "-o", "build/sample.ilc").exit_code == 0
    debug = ilc.decode(Path("build/sample.ilc").read_bytes()).debug
    assert debug is not None and debug.source_name == "../examples/sample.rob"
    shown = rl1c("dis", "build/sample.ilc")
    assert (shown.exit_code, shown.stderr) == (0, "")
    assert "| :10 A=(IMG)-180; ?A<#10" in shown.stdout


def test_the_readme_first_session_shows_the_source(tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    """`rl1c examples/sample.rob -o sample.ilc; rl1c dis sample.ilc`, as README says."""
    (tmp_path / "examples").mkdir()
    (tmp_path / "examples" / "sample.rob").write_bytes(SAMPLE.read_bytes())
    monkeypatch.chdir(tmp_path)
    assert rl1c("examples/sample.rob", "-o", "sample.ilc").exit_code == 0
    debug = ilc.decode(Path("sample.ilc").read_bytes()).debug
    assert debug is not None and debug.source_name == "examples/sample.rob"
    shown = rl1c("dis", "sample.ilc")
    assert (shown.exit_code, shown.stderr) == (0, "")
    assert "| :10 A=(IMG)-180; ?A<#10" in shown.stdout


def test_a_source_edited_since_compiling_is_not_interleaved(tmp_path: Path) -> None:
    source = tmp_path / "p.rob"
    source.write_text("A=1\nB=2\n(END)\n", encoding="utf-8")
    assert rl1c(source, "-o", tmp_path / "p.ilc").exit_code == 0
    assert "| B=2" in rl1c("dis", tmp_path / "p.ilc").stdout
    source.write_text("' a comment moves every line\nA=1\nB=2\n(END)\n", encoding="utf-8")
    for shown in (rl1c("dis", tmp_path / "p.ilc"),
                  rl1c("dis", tmp_path / "p.ilc", "--source", source)):
        assert shown.exit_code == 0 and " | " not in shown.stdout
        assert "p.rob is not the source" in shown.stderr and "compile it again" in shown.stderr


def test_dis_says_when_the_source_is_missing_or_stripped(tmp_path: Path) -> None:
    source = tmp_path / "p.rob"
    source.write_text("A=1\n(END)\n", encoding="utf-8")
    assert rl1c(source, "-o", tmp_path / "p.ilc").exit_code == 0
    assert rl1c(source, "-s", "-o", tmp_path / "stripped.ilc").exit_code == 0
    source.unlink()
    missing = rl1c("dis", tmp_path / "p.ilc")
    assert missing.exit_code == 0 and "was not found" in missing.stderr
    stripped = rl1c("dis", tmp_path / "stripped.ilc")
    assert stripped.exit_code == 0 and "no debug section" in stripped.stderr


@pytest.mark.parametrize("kind", ["fifo", "folder", "large", "binary"])
def test_dis_reads_no_fifo_nor_anything_but_a_source_the_file_names(tmp_path: Path,
                                                                     kind: str) -> None:
    named = tmp_path / "odd.rob"
    reasons = {"fifo": "is not a regular file", "folder": "is not a regular file",
               "large": "is larger than 8 MiB", "binary": "is not RL/I source"}
    match kind:
        case "fifo":
            os.mkfifo(named)
        case "folder":
            named.mkdir()
        case "large":
            named.write_bytes(b"A=1\n" * (2 * 2**20 + 1))
        case "binary":
            named.write_bytes(b"\x00\x01")
    shown = rl1c("dis", _ilc_naming(tmp_path, "odd.rob", "A=1\n"))  # a FIFO would block
    assert shown.exit_code == 0 and "        .line 1" in shown.stdout
    assert f"`{named}`, the source" in shown.stderr and reasons[kind] in shown.stderr


def test_dis_source_option_names_the_source_whatever_the_file_records(tmp_path: Path) -> None:
    elsewhere = tmp_path / "src" / "p.rob"
    elsewhere.parent.mkdir()
    elsewhere.write_text("A=1\n", encoding="utf-8")
    target = _ilc_naming(tmp_path, "/etc/passwd")
    shown = rl1c("dis", target, "--source", elsewhere)
    assert shown.exit_code == 0 and ";    1 | A=1" in shown.stdout
    missing = rl1c("dis", target, "--source", tmp_path / "none.rob")
    assert missing.exit_code == 2
    assert missing.stderr.startswith(f"error[E0100]: cannot read the --source file "
                                     f"`{tmp_path / 'none.rob'}`: no such file\n")
    compiled = rl1c("dis", target, "--source", target)  # compiled code where a source goes
    assert compiled.exit_code == 2
    assert compiled.stderr.startswith(f"error[E0100]: cannot read the --source file "
                                      f"`{target}`: it is compiled code (an .ilc file), not "
                                      "RL/I source\n")


def test_dis_and_asm_read_standard_input(tmp_path: Path) -> None:
    data = assemble(HAND_WRITTEN)
    shown = rl1c("dis", "-", stdin=data)
    assert shown.exit_code == 0 and "  0000  LDI 5" in shown.stdout
    assert "standard input has no folder" in shown.stderr
    built = rl1c("asm", "-", "-o", tmp_path / "again.ilc", stdin=shown.stdout.encode())
    assert built.exit_code == 0
    assert (tmp_path / "again.ilc").read_bytes() == data
    nowhere = rl1c("asm", "-", stdin=b"END\n")
    assert nowhere.exit_code == 2 and "give -o FILE.ilc" in nowhere.stderr
    bad = rl1c("asm", "-", "-o", "-", stdin=b"FOO\n")
    assert bad.exit_code == 1 and "<stdin>:1:1: error: unknown instruction FOO" in bad.stderr
