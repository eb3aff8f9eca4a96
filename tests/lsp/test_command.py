"""The `rl1-lsp` command: --version, --help, bad options, closed standard streams (and
`rl1-dap`'s), and serving over TCP."""

from __future__ import annotations

import asyncio
import json
import os
import socket
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import pytest
from sockets import free_port

COMMAND = [sys.executable, "-m", "rl1.lsp"]


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*COMMAND, *args], capture_output=True, text=True, timeout=60,
                          check=False)


def test_version_and_help() -> None:
    shown = run("--version")
    assert shown.returncode == 0
    assert version("rl1") in shown.stdout and "rl1-lsp" in shown.stdout
    helped = run("--help")
    assert helped.returncode == 0
    assert "--tcp HOST:PORT" in helped.stdout and "--stdio" in helped.stdout
    assert "--ws HOST:PORT" in helped.stdout


@pytest.mark.parametrize(("module", "closed", "stream"), [
    ("rl1.lsp", 1, "output"), ("rl1.lsp", 0, "input"), ("rl1.lsp.dap", 1, "output"),
])
def test_a_closed_standard_stream_is_a_usage_error(module: str, closed: int,
                                                    stream: str) -> None:
    # Python leaves a stream the shell closed (`>&-`) as None: an AttributeError before.
    failed = subprocess.run([sys.executable, "-m", module], stdin=subprocess.DEVNULL,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            timeout=60, check=False, preexec_fn=lambda: os.close(closed))
    assert failed.returncode == 2, failed.stderr
    name = "rl1-dap" if module.endswith("dap") else "rl1-lsp"
    assert failed.stderr.endswith(f"{name}: error: standard {stream} is closed: a client "
                                  "starts this server with its standard input and output "
                                  "as pipes\n")


@pytest.mark.parametrize(("program", "args", "said"), [
    ("rl1-lsp", ["--bogus"], "unrecognized arguments: --bogus"),
    ("rl1-lsp", ["--tcp", "2087"],
     "argument --tcp: expected HOST:PORT such as 127.0.0.1:2087, got '2087'"),
    ("rl1-dap", ["--bogus"], "unrecognized arguments: --bogus"),
])
def test_a_malformed_command_line_is_said_as_rl1cs_are(program: str, args: list[str],
                                                        said: str) -> None:
    # The installed programs, as an editor starts them; click said `Usage: ...` then
    # `Error: No such option: --bogus` before, unlike every rl1c command.
    script = Path(sys.executable).with_name(program)
    failed = subprocess.run([script, *args], capture_output=True, text=True, timeout=60,
                            stdin=subprocess.DEVNULL, check=False)
    rl1c = subprocess.run([script.with_name("rl1c"), "check", *args], capture_output=True,
                          text=True, timeout=60, check=False)
    assert failed.returncode == rl1c.returncode == 2
    assert failed.stderr == f"usage: {program} [OPTIONS]\n{program}: error: {said}\n"
    assert rl1c.stderr.splitlines()[0].startswith("usage: rl1c check ")


@pytest.mark.parametrize("option", ["--tcp", "--ws"])
@pytest.mark.parametrize("value", ["2087", "localhost:", "host:port", "h:70000"])
def test_a_bad_address_is_a_usage_error(option: str, value: str) -> None:
    failed = run(option, value)
    assert failed.returncode == 2
    assert "HOST:PORT" in failed.stderr and "Traceback" not in failed.stderr


@pytest.mark.parametrize("options", [
    ["--stdio", "--tcp", "127.0.0.1:2087"], ["--tcp", "127.0.0.1:2087", "--ws", "127.0.0.1:2088"],
    ["--stdio", "--ws", "127.0.0.1:2087"]])
def test_two_transports_together_are_a_usage_error(options: list[str]) -> None:
    failed = run(*options)
    assert failed.returncode == 2
    assert "choose one of --stdio, --tcp and --ws" in failed.stderr


@pytest.mark.parametrize("option", ["--tcp", "--ws"])
def test_a_port_in_use_is_a_clear_error(option: str) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        failed = run(option, f"127.0.0.1:{taken.getsockname()[1]}")
    assert failed.returncode == 1
    assert "cannot listen on 127.0.0.1:" in failed.stderr and "another port" in failed.stderr
    assert "Traceback" not in failed.stderr


def frame(message: dict[str, object]) -> bytes:
    body = json.dumps(message).encode()
    return f"Content-Length: {len(body)}\r\n\r\n".encode() + body


async def read_frame(reader: asyncio.StreamReader) -> dict[str, object]:
    length = 0
    while (header := await reader.readline()) != b"\r\n":
        if header.lower().startswith(b"content-length:"):
            length = int(header.split(b":")[1])
    answer: dict[str, object] = json.loads(await reader.readexactly(length))
    return answer


@pytest.mark.asyncio
async def test_serves_over_tcp() -> None:
    port = free_port()
    server = await asyncio.create_subprocess_exec(
        *COMMAND, "--tcp", f"127.0.0.1:{port}", stderr=asyncio.subprocess.PIPE)
    try:
        async with asyncio.timeout(60):
            while True:
                try:
                    reader, writer = await asyncio.open_connection("127.0.0.1", port)
                    break
                except OSError:
                    await asyncio.sleep(0.1)
            writer.write(frame({"jsonrpc": "2.0", "id": 1, "method": "initialize",
                                "params": {"processId": None, "rootUri": None,
                                           "capabilities": {}}}))
            answer = await read_frame(reader)
            assert answer["id"] == 1
            result = answer["result"]
            assert isinstance(result, dict)
            assert result["serverInfo"]["name"] == "rl1-lsp"
            assert result["capabilities"]["hoverProvider"]
            writer.close()
    finally:
        server.kill()
        await server.wait()
