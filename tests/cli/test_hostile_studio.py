"""`rl1c studio` against a hostile client, as a real one speaks to it (urllib, the
websockets library): every request without the right Host, token or Origin is refused
with 403; no path reaches outside the folder (`..`, an absolute path, a symbolic link
out, /dev/zero through a link) or opens what is not a regular file (a FIFO, a link
loop, a folder), and none of them gives the file's text; messages that are no JSON or
no request are answered with their error; and the server serves on after all of it."""

from __future__ import annotations

import json
import re
import signal
import subprocess
import sys
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.slow  # a studio server of its own

RL1C = Path(sys.executable).with_name("rl1c")
SECRET = "' secret outside the folder\n"


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[int, str, Path]]:
    """A studio serving a folder with hostile neighbours: its port, token and folder."""
    outside = tmp_path_factory.mktemp("outside")
    (outside / "secret.rob").write_text(SECRET)
    folder = tmp_path_factory.mktemp("studio")
    (folder / "main.rob").write_text("(END)\n")
    (folder / "out.rob").symlink_to(outside / "secret.rob")
    (folder / "up").symlink_to(outside)
    (folder / "zero.rob").symlink_to("/dev/zero")
    (folder / "loop.rob").symlink_to("loop.rob")
    (folder / "folder.rob").mkdir()
    subprocess.run(["mkfifo", str(folder / "fifo.rob")], check=True)
    server = subprocess.Popen([str(RL1C), "studio", "--no-browser", "--port", "0"],
                              cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)
    try:  # the server ends with the fixture, whatever fails
        assert server.stdout is not None
        address = re.search(r"http://127\.0\.0\.1:(\d+)/\?token=(\S+)",
                            server.stdout.readline())
        assert address is not None
        yield int(address[1]), address[2], outside
        server.send_signal(signal.SIGINT)
        _, said = server.communicate(timeout=60)
        assert server.returncode == 130
        assert "Traceback" not in said
    finally:
        server.kill()
        server.wait(60)


def status_of(port: int, path: str, headers: dict[str, str]) -> int:
    request = urllib.request.Request(f"http://127.0.0.1:{port}{path}", headers=headers)
    try:
        with urllib.request.urlopen(request, timeout=30) as answer:
            return int(answer.status)
    except urllib.error.HTTPError as error:
        return error.code


@pytest.mark.parametrize(("path", "headers"), [
    ("/", {}), ("/?token=x", {}), ("/?token=", {}), ("/?token={t}x", {}),
    ("/?token={t}", {"Host": "evil.example"}), ("/?token={t}", {"Host": "127.0.0.1"}),
    ("/?token={t}", {"Host": "127.0.0.1:{p}.evil.example"}),
    ("/?token={t}", {"Origin": "http://evil.example"}), ("/?token={t}", {"Origin": "null"}),
])
def test_a_request_without_the_right_host_token_or_origin_is_forbidden(
        studio: tuple[int, str, Path], path: str, headers: dict[str, str]) -> None:
    port, token, _ = studio
    fill = {"t": token, "p": str(port)}
    assert status_of(port, path.format(**fill),
                     {key: value.format(**fill) for key, value in headers.items()}) == 403


def call(port: int, token: str, messages: list[Any]) -> list[dict[str, Any]]:
    """The answers to `messages` (each sent as a text frame as it is, or as JSON) on one
    /studio connection."""
    from websockets.sync.client import connect

    with connect(f"ws://127.0.0.1:{port}/studio?token={token}", open_timeout=30) as client:
        answers = []
        for message in messages:
            client.send(message if isinstance(message, str) else json.dumps(message))
            answers.append(json.loads(client.recv(timeout=30)))
        return answers


@pytest.mark.parametrize("path", [
    "../secret.rob", "/etc/passwd", "out.rob", "up/secret.rob", "zero.rob", "fifo.rob",
    "loop.rob", "folder.rob", "main.rob\x00", "", "main.rob/../out.rob"])
def test_no_path_reaches_outside_the_folder_or_a_file_that_is_not_regular(
        studio: tuple[int, str, Path], path: str) -> None:
    port, token, outside = studio
    for method, params in (("files/read", {"path": path}),
                           ("files/save", {"path": path, "text": "A=1\n"})):
        [answer] = call(port, token, [{"jsonrpc": "2.0", "id": 1, "method": method,
                                       "params": params}])
        assert answer["error"]["code"] in (-32001, -32002), answer
        assert "secret" not in json.dumps(answer.get("error", {}).get("data", ""))
    assert (outside / "secret.rob").read_text() == SECRET
    assert sorted(entry.name for entry in outside.iterdir()) == ["secret.rob"]


@pytest.mark.parametrize(("raw", "code"), [
    ("not json", -32700), ("[" * 100_000, -32700), ("{}", -32600), ("[]", -32600),
    ('"x"', -32600), ("null", -32600), ('{"jsonrpc": "2.0", "id": {}, "method": "palette"}',
                                        -32600),
    ('{"jsonrpc": "2.0", "id": 1, "method": "nope", "params": {}}', -32601),
    ('{"jsonrpc": "2.0", "id": 1, "method": "files/read", "params": []}', -32602),
    ('{"jsonrpc": "2.0", "id": 1, "method": "run/launch", "params": '
     '{"program": {"text": "(END)"}, "seed": -1}}', -32602),
])
def test_a_message_that_is_no_request_gets_its_error_and_the_server_goes_on(
        studio: tuple[int, str, Path], raw: str, code: int) -> None:
    port, token, _ = studio
    answer, after = call(port, token, [raw, {"jsonrpc": "2.0", "id": 2, "method": "palette",
                                             "params": {}}])
    assert answer["error"]["code"] == code
    assert after["id"] == 2 and after["result"]["builtins"]
