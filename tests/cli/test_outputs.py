"""Where rl1c writes: a regular file is replaced all at once, a FIFO or a device is
written to and never replaced, a read-only file is refused unless --force, a directory
is refused, and a symbolic link stays a link."""

import os
import stat
import threading
from pathlib import Path

import pytest
from support import SAMPLE
from support.cli import rl1c

UNFORMATTED = "A=1;B=2\n(END)\n"


@pytest.fixture
def source(tmp_path: Path) -> Path:
    copy = tmp_path / "sample.rob"
    copy.write_bytes(SAMPLE.read_bytes())
    return copy


def test_a_fifo_is_written_as_a_stream_not_replaced(source: Path, tmp_path: Path) -> None:
    fifo = tmp_path / "out.fifo"
    os.mkfifo(fifo)
    received: list[bytes] = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_bytes()))
    reader.start()
    result = rl1c(source, "-o", fifo)
    reader.join(timeout=30)
    assert result.exit_code == 0, result.output
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    assert received and received[0].startswith(b"RLIC")


def test_a_character_device_is_written_to_not_replaced(source: Path, tmp_path: Path) -> None:
    device = tmp_path / "null"
    try:  # a private /dev/null, so that a regression cannot replace the real one
        os.mknod(device, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except PermissionError:
        pytest.skip("making a device node needs root")
    result = rl1c(source, "-o", device)
    assert result.exit_code == 0, result.output
    assert stat.S_ISCHR(device.stat().st_mode)


def test_a_read_only_output_is_refused_unless_forced(source: Path, tmp_path: Path) -> None:
    target = tmp_path / "ro.ilc"
    target.write_bytes(b"old")
    target.chmod(0o444)
    refused = rl1c(source, "-o", target)
    assert refused.exit_code == 2
    assert (f"error[E0100]: cannot write the output file `{target}`: it is read-only; give "
            "--force") in refused.stderr
    assert target.read_bytes() == b"old"
    forced = rl1c(source, "-o", target, "--force")
    assert forced.exit_code == 0, forced.output
    assert target.read_bytes().startswith(b"RLIC")
    assert stat.S_IMODE(target.stat().st_mode) == 0o444


def test_asm_refuses_a_read_only_output_too(tmp_path: Path) -> None:
    text, target = tmp_path / "x.ils", tmp_path / "x.ilc"
    text.write_text("END\n", encoding="utf-8")
    target.write_bytes(b"old")
    target.chmod(0o444)
    assert rl1c("asm", text, "-o", target).exit_code == 2
    assert target.read_bytes() == b"old"
    assert rl1c("asm", text, "-o", target, "--force").exit_code == 0


def test_fmt_leaves_a_read_only_program_as_it_is_unless_forced(tmp_path: Path) -> None:
    program = tmp_path / "p.rob"
    program.write_text(UNFORMATTED, encoding="utf-8")
    program.chmod(0o444)
    refused = rl1c("fmt", program)
    assert refused.exit_code == 2 and "it is read-only" in refused.stderr
    assert program.read_text(encoding="utf-8") == UNFORMATTED
    assert rl1c("fmt", "--force", program).exit_code == 0
    assert program.read_text(encoding="utf-8") != UNFORMATTED
    assert stat.S_IMODE(program.stat().st_mode) == 0o444


def test_a_directory_is_refused(source: Path, tmp_path: Path) -> None:
    folder = tmp_path / "out"
    folder.mkdir()
    result = rl1c(source, "-o", folder)
    assert result.exit_code == 2
    assert f"error[E0100]: cannot write the output file `{folder}`: it is a directory" \
        in result.stderr
    assert folder.is_dir()


def test_a_symbolic_link_stays_a_link_to_the_written_file(source: Path, tmp_path: Path) -> None:
    link, real = tmp_path / "link.ilc", tmp_path / "real.ilc"
    link.symlink_to(real.name)
    assert rl1c(source, "-o", link).exit_code == 0
    assert link.is_symlink() and real.read_bytes().startswith(b"RLIC")
