"""`rl1c studio` as a user starts it (spec/studio.md, "Starting"): the address printed
with its token, the page served there, Ctrl-C stopping it with status 130; a FILE
outside the folder, of another kind, or a port in use refused with status 2."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from served import ADDRESS, RL1C, sample_folder
from support.cli import rl1c
from websockets.sync.client import connect

TIMEOUT = 60


def test_it_prints_its_address_serves_there_and_stops_on_ctrl_c(tmp_path: Path) -> None:
    folder = sample_folder(tmp_path)
    studio = subprocess.Popen([*RL1C, "studio", "sample.rob", "--no-browser"], cwd=folder,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert studio.stdout is not None
        shown = ADDRESS.match(studio.stdout.readline().rstrip("\n"))
        assert shown is not None
        assert shown["folder"] == str(folder.resolve())
        assert len(shown["token"]) >= 43  # 32 random bytes
        address = f"ws://127.0.0.1:{shown['port']}/studio?token={shown['token']}"
        with connect(address, open_timeout=TIMEOUT) as page:
            page.send(json.dumps({"jsonrpc": "2.0", "id": 1, "method": "initialize"}))
            hello = json.loads(page.recv(timeout=TIMEOUT))["result"]
        assert (hello["program"], hello["world"]) == ("sample.rob", "sample.world.toml")
        studio.send_signal(signal.SIGINT)
        _, stderr = studio.communicate(timeout=TIMEOUT)
        assert studio.returncode == 130
        assert stderr == "rl1c: interrupted\n"
    finally:
        studio.kill()
        studio.wait(TIMEOUT)


def test_a_program_outside_the_folder_is_refused(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    inside = tmp_path / "inside"
    inside.mkdir()
    (tmp_path / "outside.rob").write_text("(END)\n")
    monkeypatch.chdir(inside)
    ran = rl1c("studio", "../outside.rob", "--no-browser")
    assert ran.exit_code == 2
    assert "rl1c studio: error: `" in ran.stderr and "has a `..`" in ran.stderr
    ran = rl1c("studio", str(tmp_path / "outside.rob"), "--no-browser")
    assert ran.exit_code == 2
    assert "the studio uses no file outside it" in ran.stderr


def test_a_world_outside_the_folder_is_refused(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(sample_folder(tmp_path))
    ran = rl1c("studio", "--world", "/etc/hostname", "--no-browser")
    assert ran.exit_code == 2
    assert "outside" in ran.stderr


def test_a_file_that_is_no_program_is_refused(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(sample_folder(tmp_path))
    ran = rl1c("studio", "sample.world.toml", "--no-browser")
    assert ran.exit_code == 2
    assert "a .rob file" in ran.stderr


def test_a_port_in_use_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(sample_folder(tmp_path))
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        ran = rl1c("studio", "--port", str(taken.getsockname()[1]), "--no-browser")
    assert ran.exit_code == 2
    assert "cannot listen on 127.0.0.1:" in ran.stderr
    assert "choose another port" in ran.stderr
    assert "Traceback" not in ran.stderr


def test_an_address_it_cannot_print_is_said_as_any_output_is_not_as_the_port(
        tmp_path: Path) -> None:
    # The address, with its token, is the only way in: a studio nobody can reach ends.
    ended = subprocess.run([*RL1C, "studio", "--no-browser"], cwd=sample_folder(tmp_path),
                           capture_output=True, text=True, timeout=60, check=False,
                           preexec_fn=lambda: os.close(1))
    assert ended.returncode == 2
    assert ended.stderr == ("rl1c: error: cannot write the output: standard output is "
                            "closed; send it to a file, a pipe or /dev/null (`> FILE`, not "
                            "`>&-`)\n")


def test_without_the_websockets_package_it_says_which_extra_to_install(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, "websockets", None)  # `import websockets` fails
    ran = rl1c("studio", "--no-browser")
    assert ran.exit_code == 2
    assert ran.stderr == ("rl1c studio: error: the studio needs the websockets package: "
                          "pip install 'rl1[ws]'\n")
