"""The one folder the studio reads and writes (spec/studio.md, "Files"): `..`, absolute
paths outside, symbolic links leading out, FIFOs and devices refused; saving only the
studio's kinds of file, all at once; the listing."""

from __future__ import annotations

import os
import threading
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rl1.lsp.studio.files import MAX_FILE_BYTES, Entry, Folder, Refused, Unusable


@pytest.fixture
def folder(tmp_path: Path) -> Folder:
    root = tmp_path / "robots"
    (root / "worlds").mkdir(parents=True)
    (root / "a.rob").write_text("(END)\n")
    (root / "worlds" / "w.world.toml").write_text("[floor]\n")
    (tmp_path / "outside.rob").write_text("secret\n")
    return Folder(root)


def test_a_file_inside_is_read_by_a_relative_or_an_absolute_path(folder: Folder) -> None:
    assert folder.read("a.rob") == b"(END)\n"
    assert folder.read(str(folder.root / "a.rob")) == b"(END)\n"
    assert folder.read("worlds/w.world.toml") == b"[floor]\n"


@pytest.mark.parametrize("path", ["../outside.rob", "worlds/../a.rob", "..", "a.rob/..",
                                  "worlds/../../outside.rob"])
def test_dot_dot_is_refused_even_when_it_stays_inside(folder: Folder, path: str) -> None:
    with pytest.raises(Refused, match=r"`\.\.`"):
        folder.read(path)
    with pytest.raises(Refused):
        folder.save(path, b"")


def test_an_absolute_path_outside_is_refused(folder: Folder) -> None:
    outside = str(folder.root.parent / "outside.rob")
    with pytest.raises(Refused, match="outside"):
        folder.read(outside)
    with pytest.raises(Refused, match="outside"):
        folder.save(outside, b"(END)\n")
    assert (folder.root.parent / "outside.rob").read_text() == "secret\n"


def test_a_symbolic_link_leading_out_is_refused(folder: Folder) -> None:
    (folder.root / "link.rob").symlink_to(folder.root.parent / "outside.rob")
    (folder.root / "out").symlink_to(folder.root.parent)
    for path in ("link.rob", "out/outside.rob"):
        with pytest.raises(Refused, match="outside"):
            folder.read(path)
        with pytest.raises(Refused, match="outside"):
            folder.save(path, b"overwritten")
    assert (folder.root.parent / "outside.rob").read_text() == "secret\n"


def test_a_loop_of_links_is_refused(folder: Folder) -> None:
    (folder.root / "x.rob").symlink_to(folder.root / "y.rob")
    (folder.root / "y.rob").symlink_to(folder.root / "x.rob")
    with pytest.raises(Refused):
        folder.read("x.rob")


def test_a_fifo_is_refused_without_waiting_for_a_writer(folder: Folder) -> None:
    os.mkfifo(folder.root / "pipe.rob")
    done = threading.Event()

    def read() -> None:
        with pytest.raises(Refused, match="a FIFO"):
            folder.read("pipe.rob")
        done.set()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    assert done.wait(30), "reading a FIFO waited for a writer"
    with pytest.raises(Refused, match="a FIFO"):
        folder.save("pipe.rob", b"(END)\n")


def test_a_device_is_refused(tmp_path: Path) -> None:
    # A folder holding a device: /dev itself, whose null device is inside it.
    with pytest.raises(Refused, match="a device"):
        Folder("/dev").read("null")
    with pytest.raises(Refused, match="folder"):
        Folder(tmp_path).read(".")


@pytest.mark.parametrize("path", ["", "a\x00.rob"])
def test_no_path_is_refused(folder: Folder, path: str) -> None:
    with pytest.raises(Refused, match="no file's path"):
        folder.read(path)


def test_a_missing_file_says_so(folder: Folder) -> None:
    with pytest.raises(Unusable, match="no such file"):
        folder.read("nothing.rob")


def test_a_file_too_large_is_not_read(folder: Folder) -> None:
    (folder.root / "big.rob").write_bytes(b"'" * (MAX_FILE_BYTES + 1))
    with pytest.raises(Unusable, match="larger than 8 MiB"):
        folder.read("big.rob")


def test_saving_replaces_the_file_and_keeps_a_link_a_link(folder: Folder) -> None:
    (folder.root / "alias.rob").symlink_to(folder.root / "a.rob")
    folder.save("alias.rob", b"(MOV 1,1)\n")
    assert (folder.root / "alias.rob").is_symlink()
    assert (folder.root / "a.rob").read_bytes() == b"(MOV 1,1)\n"
    folder.save("worlds/new.sensors.json", b"{}")
    assert (folder.root / "worlds" / "new.sensors.json").read_bytes() == b"{}"
    assert sorted(os.listdir(folder.root / "worlds")) == ["new.sensors.json", "w.world.toml"]


@pytest.mark.parametrize("path", ["Makefile", "a.rob.sh", "notes.toml", ".bashrc"])
def test_only_the_studios_kinds_of_file_are_written(folder: Folder, path: str) -> None:
    with pytest.raises(Refused, match="no file the studio writes"):
        folder.save(path, b"")
    assert not (folder.root / path).exists()


def test_a_link_with_a_studio_name_to_another_kind_of_file_is_not_written(folder: Folder
                                                                          ) -> None:
    (folder.root / "Makefile").write_text("all:\n")
    (folder.root / "make.rob").symlink_to(folder.root / "Makefile")
    with pytest.raises(Refused, match="`Makefile` is no file the studio writes"):
        folder.save("make.rob", b"(END)\n")
    assert (folder.root / "Makefile").read_text() == "all:\n"


def test_saving_into_a_missing_folder_says_to_make_it(folder: Folder) -> None:
    with pytest.raises(Unusable, match="does not exist"):
        folder.save("nowhere/a.rob", b"")


@pytest.mark.parametrize("path", ["a.rob/", "a.rob/.", "./a.rob/"])
def test_a_path_naming_a_folder_is_refused_though_a_file_has_its_name(folder: Folder,
                                                                       path: str) -> None:
    with pytest.raises(Refused, match="folder"):
        folder.read(path)


def test_the_listing_leaves_out_what_is_no_regular_file(folder: Folder) -> None:
    os.mkfifo(folder.root / "pipe.rob")
    entries, _ = folder.listing()
    assert "pipe.rob" not in [entry.path for entry in entries]
    assert "a.rob" in [entry.path for entry in entries]


def test_the_listing_has_the_studios_files_sorted(folder: Folder) -> None:
    (folder.root / ".hidden").mkdir()
    (folder.root / ".hidden" / "h.rob").write_text("")
    (folder.root / "node_modules").mkdir()
    (folder.root / "node_modules" / "n.rob").write_text("")
    (folder.root / "s.sensors.json").write_text("{}")
    (folder.root / "notes.txt").write_text("")
    (folder.root / "out.rob").symlink_to(folder.root.parent / "outside.rob")
    entries, truncated = folder.listing()
    assert entries == [Entry("a.rob", "program", 6), Entry("s.sensors.json", "sensors", 2),
                       Entry("worlds/w.world.toml", "world", 8)]
    assert not truncated


@given(st.lists(st.sampled_from(["a", ".", "/", "..", "b.rob", "\\", "~", "\x00", "out",
                                 "/tmp", "%2e"]), max_size=10).map("".join))
def test_any_path_is_refused_or_inside(tmp_path_factory: pytest.TempPathFactory,
                                       path: str) -> None:
    root = tmp_path_factory.getbasetemp() / "property"
    root.mkdir(exist_ok=True)
    if not (root / "out").is_symlink():
        (root / "out").symlink_to(root.parent)
    folder = Folder(root)
    try:
        resolved = folder.resolve(path)
    except Refused:
        return
    assert resolved.is_relative_to(folder.root)
    assert resolved == resolved.resolve()
