"""`rl1-dap` driven by a DAP client over its real protocol: the server in a subprocess,
each message framed with Content-Length on its standard input and output, the answers
compared as exact JSON where the protocol fixes them."""

from __future__ import annotations

import json
import os
import queue
import subprocess
import sys
import threading
from pathlib import Path
from typing import IO, Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import SAMPLE, SAMPLE_SENSORS

from rl1.compiler.debugger import Session, Stop
from rl1.lsp.dap import CAPABILITIES, Adapter, Refused

WORLD = SAMPLE.parent / "sample.world.toml"
TIMEOUT = 60


def _read_messages(stream: IO[bytes], into: queue.Queue[dict[str, Any] | None]) -> None:
    while True:
        length = None
        while (line := stream.readline()) not in (b"\r\n", b""):
            name, _, value = line.decode("ascii").partition(":")
            if name.lower() == "content-length":
                length = int(value)
        if not line or length is None:
            into.put(None)
            return
        into.put(json.loads(stream.read(length)))


class Client:
    """A DAP client: requests numbered from 1, every message the server sends kept."""

    def __init__(self) -> None:
        self.server = subprocess.Popen([sys.executable, "-m", "rl1.lsp.dap"],
                                       stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                       stderr=subprocess.PIPE)
        assert self.server.stdin is not None and self.server.stdout is not None
        self.messages: queue.Queue[dict[str, Any] | None] = queue.Queue()
        self.events: list[dict[str, Any]] = []
        threading.Thread(target=_read_messages, args=(self.server.stdout, self.messages),
                         daemon=True).start()
        self.seq = 0

    def send_raw(self, data: bytes) -> None:
        assert self.server.stdin is not None
        self.server.stdin.write(data)
        self.server.stdin.flush()

    def send(self, command: str, arguments: dict[str, Any] | None = None) -> int:
        self.seq += 1
        message: dict[str, Any] = {"seq": self.seq, "type": "request", "command": command}
        if arguments is not None:
            message["arguments"] = arguments
        body = json.dumps(message).encode()
        self.send_raw(b"Content-Length: %d\r\n\r\n%s" % (len(body), body))
        return self.seq

    def _next(self) -> dict[str, Any]:
        message = self.messages.get(timeout=TIMEOUT)
        assert message is not None, "the server closed its output"
        return message

    def request(self, command: str, arguments: dict[str, Any] | None = None
                ) -> dict[str, Any]:
        """The response to the request, keeping the events sent before it."""
        seq = self.send(command, arguments)
        while (message := self._next())["type"] != "response":
            self.events.append(message)
        assert message["request_seq"] == seq and message["command"] == command
        return message

    def event(self, name: str) -> dict[str, Any]:
        """The first event called `name` (of those kept, else of those to come), taken
        from those kept."""
        while True:
            for index, message in enumerate(self.events):
                if message["event"] == name:
                    return self.events.pop(index)
            message = self._next()
            assert message["type"] == "event", message
            self.events.append(message)

    def variables(self, reference: int) -> dict[str, str]:
        response = self.request("variables", {"variablesReference": reference})
        return {v["name"]: v["value"] for v in response["body"]["variables"]}

    def line(self) -> int:
        response = self.request("stackTrace", {"threadId": 1})
        (frame,) = response["body"]["stackFrames"]
        return int(frame["line"])

    def close(self) -> tuple[int, str]:
        self.request("disconnect", {})
        status = self.server.wait(timeout=TIMEOUT)
        assert self.server.stderr is not None
        return status, self.server.stderr.read().decode()


@pytest.fixture
def client() -> Any:
    started = Client()
    yield started
    if started.server.poll() is None:
        started.server.kill()
        started.server.wait()


def _launched(client: Client, **arguments: Any) -> None:
    client.request("initialize", {"adapterID": "rl1", "linesStartAt1": True})
    response = client.request("launch", arguments)
    assert response["success"], response
    client.event("initialized")


def test_initialize_answers_the_capabilities_as_exact_json(client: Client) -> None:
    response = client.request("initialize", {"adapterID": "rl1"})
    assert response == {"seq": 1, "type": "response", "request_seq": 1, "success": True,
                        "command": "initialize", "body": CAPABILITIES}
    assert json.loads(json.dumps(CAPABILITIES)) == {
        "supportsConfigurationDoneRequest": True, "supportsConditionalBreakpoints": True,
        "supportsFunctionBreakpoints": True, "supportsRestartRequest": True,
        "supportsSteppingGranularity": True, "supportsExceptionInfoRequest": True,
        "supportsEvaluateForHovers": True,
        "exceptionBreakpointFilters": [{
            "filter": "lost-line", "label": "Lost lines",
            "description": "Stop where the program jumps to a lost-line handler (:96-:99)",
            "default": False}]}
    assert client.close() == (0, "")


def test_listing_1_stops_at_line_20_steps_and_runs_to_its_end(client: Client) -> None:
    _launched(client, program=str(SAMPLE), sensors=str(SAMPLE_SENSORS))
    response = client.request("setBreakpoints", {
        "source": {"path": str(SAMPLE)},
        "breakpoints": [{"line": 20}, {"line": 22, "condition": "A<5"}]})
    assert response["body"] == {"breakpoints": [
        {"verified": True, "line": 20},
        {"verified": False, "line": 22, "message": (
            "the condition `A<5` compares with 5, and a condition compares with 0 (`<` "
            "after a value is a shift): write `A-5<0`")}]}
    assert client.request("configurationDone")["success"]
    stopped = client.event("stopped")
    assert {k: v for k, v in stopped.items() if k != "seq"} == {
        "type": "event", "event": "stopped",
        "body": {"reason": "breakpoint", "threadId": 1, "allThreadsStopped": True}}
    assert client.request("threads")["body"] == {"threads": [{"id": 1, "name": "program"}]}
    frames = client.request("stackTrace", {"threadId": 1})["body"]
    assert frames == {"totalFrames": 1, "stackFrames": [{
        "id": 1, "name": "program", "line": 20, "column": 1,
        "source": {"name": "sample.rob", "path": str(SAMPLE.resolve())}}]}
    scopes = client.request("scopes", {"frameId": 1})["body"]["scopes"]
    assert [(s["name"], s["variablesReference"]) for s in scopes] == [
        ("Variables", 1), ("Reserved variables", 2), ("Device", 3)]
    user = client.variables(1)
    assert list(user) == list("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqr@")
    assert {name: value for name, value in user.items() if value != "0"} == {
        "A": "60", "C": "589", "D": "450", "L": "100", "U": "160"}
    assert client.variables(2) == {"s": "0", "t": "0", "u": "0", "v": "0", "w": "40",
                                   "x": "128", "y": "100", "z": "0"}
    assert client.variables(3) == {"time (ms)": "2000", "tracing mode": "0",
                                   "motion": "null",
                                   "last readings": '{"IMG": [40, 128, 100, 0]}'}
    assert client.request("evaluate", {"expression": "U-L", "context": "watch"})[
        "body"] == {"result": "60", "variablesReference": 0}
    refused = client.request("evaluate", {"expression": "(IMG)", "context": "hover"})
    assert (refused["success"], refused["message"]) == (False, (
        "`(IMG)` calls a built-in, which would drive the vehicle: use the variables it "
        "writes (x, y, w after (IMG)) instead"))
    calls = [e["body"]["output"] for e in client.events if e["event"] == "output"]
    assert calls[0] == "0 ms, line 2: CAM Z\n" and calls[-1].endswith(
        "line 18: CAM P 589\n")

    client.request("next", {"threadId": 1})
    assert client.event("stopped")["body"]["reason"] == "step"
    assert client.line() == 21
    client.request("stepIn", {"threadId": 1, "granularity": "instruction"})
    assert client.event("stopped")["body"]["reason"] == "step"
    assert client.line() == 22
    assert client.request("continue", {"threadId": 1})["body"] == {"allThreadsContinued": True}
    assert client.event("exited")["body"] == {"exitCode": 0}
    client.event("terminated")
    assert client.close() == (0, "")


def test_a_fault_is_an_exception_on_its_line_then_the_end(client: Client,
                                                         tmp_path: Path) -> None:
    program = tmp_path / "fault.rob"
    program.write_text("A=5\nA=A-10\n(TIM A)\n(END)\n")
    _launched(client, program=str(program))
    client.request("configurationDone")
    message = "argument tenths of (TIM) is -5 (the value of A), outside 1..100"
    assert client.event("stopped")["body"] == {
        "reason": "exception", "threadId": 1, "allThreadsStopped": True,
        "description": f"E1010: {message}", "text": f"E1010: {message}"}
    assert client.request("exceptionInfo", {"threadId": 1})["body"] == {
        "exceptionId": "E1010", "description": message, "breakMode": "always"}
    assert client.line() == 3
    client.request("continue", {"threadId": 1})
    assert client.event("exited")["body"] == {"exitCode": 10}
    client.event("terminated")
    assert client.close() == (0, "")


def test_a_used_up_budget_stops_saying_what_to_do(client: Client, tmp_path: Path) -> None:
    program = tmp_path / "loop.rob"
    program.write_text(":10 A=A+1\n#10\n")
    _launched(client, program=str(program), budget=50)
    client.request("configurationDone")
    description = client.event("stopped")["body"]["description"]
    assert description.startswith(
        "E1012: the program ran more than 50 instructions without ending; if the program "
        "should run longer, give it a larger budget")
    client.request("continue", {"threadId": 1})
    assert client.event("exited")["body"] == {"exitCode": 12}


def test_a_call_breakpoint_on_the_simulator_shows_the_vehicle(client: Client) -> None:
    _launched(client, program=str(SAMPLE), world=str(WORLD))
    response = client.request("setFunctionBreakpoints", {
        "breakpoints": [{"name": "IMG"}, {"name": "IMAGE"}]})
    assert response["body"]["breakpoints"][0] == {"verified": True}
    assert response["body"]["breakpoints"][1]["verified"] is False
    assert "`IMAGE` is no built-in to stop at" in response["body"]["breakpoints"][1]["message"]
    client.request("configurationDone")
    assert client.event("stopped")["body"] == {
        "reason": "function breakpoint", "threadId": 1, "allThreadsStopped": True,
        "description": "(IMG)", "text": "(IMG)"}
    assert client.line() == 4
    device = client.variables(3)
    assert device["tracing mode"] == "3" and device["motion"] == "MOV"
    assert device["camera pan (pulses)"] == "392" and device["camera tilt"] == "down"
    assert {"x (cm)", "y (cm)", "heading (degrees)", "wheel speeds (units)",
            "steering (degrees)"} <= set(device)
    client.close()


def test_pause_stops_a_running_program_and_restart_begins_again(client: Client,
                                                               tmp_path: Path) -> None:
    program = tmp_path / "loop.rob"
    program.write_text(":10 A++\n#10\n")
    # At -O0: -O1 drops the A++ that no one sees in a loop that never ends.
    _launched(client, program=str(program), budget=10**9, stopOnEntry=True, level=0)
    client.request("configurationDone")
    assert client.event("stopped")["body"]["reason"] == "entry"
    client.request("continue", {"threadId": 1})
    refused = client.request("next", {"threadId": 1})
    assert (refused["success"], refused["message"]) == (
        False, "the program is running: pause it first")
    client.request("pause", {"threadId": 1})
    assert client.event("stopped")["body"]["reason"] == "pause"
    assert int(client.variables(1)["A"]) != 0
    client.request("restart", {})
    assert client.event("stopped")["body"]["reason"] == "entry"
    assert client.variables(1)["A"] == "0"
    client.close()


def test_what_cannot_be_launched_is_refused_with_why(client: Client, tmp_path: Path) -> None:
    client.request("initialize", {})
    missing = client.request("launch", {"program": str(tmp_path / "none.rob")})
    assert missing["success"] is False and "none.rob" in missing["message"]
    broken = tmp_path / "broken.rob"
    broken.write_text("A=(MOV 1,1)\n")
    refused = client.request("launch", {"program": str(broken)})
    assert refused["success"] is False
    assert refused["message"].startswith(f"the program has errors, so it cannot run: {broken}:1:")
    both = client.request("launch", {"program": str(SAMPLE), "sensors": "a", "world": "b"})
    assert both["message"] == ("give `sensors` (a sensor script) or `world` (the simulator's "
                               "world), not both")
    assert client.request("scopes", {"frameId": 1})["success"] is True
    unknown = client.request("readMemory", {})
    assert unknown["message"] == "rl1-dap does not support the request 'readMemory'"
    early = client.request("setBreakpoints", {"breakpoints": []})
    assert early["message"] == "no program is launched: send launch first"


def test_broken_input_is_skipped_and_said_on_standard_error(client: Client) -> None:
    client.send_raw(b"Content-Length: 5\r\n\r\nnot j")
    client.send_raw(b"Content-Length: 2\r\n\r\n[]")
    client.send_raw(b"garbage\r\n\r\n")
    assert client.request("threads")["success"] is True
    status, errors = client.close()
    assert status == 0
    assert "a message that is no JSON was skipped" in errors
    assert "a message that is no DAP request (type, seq and command) was skipped" in errors
    assert "skipped a line that is no header" in errors


json_values = st.recursive(
    st.none() | st.booleans() | st.integers(-2**40, 2**40) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner,
                                                                max_size=3),
    max_leaves=8)
# The keys each request reads, given any values (with any other key now and then).
KEYS = {
    "initialize": ("adapterID",), "launch": ("program", "sensors", "world", "level",
                                             "budget", "seed", "stopOnEntry"),
    "setBreakpoints": ("breakpoints", "source"), "setFunctionBreakpoints": ("breakpoints",),
    "setExceptionBreakpoints": ("filters",), "configurationDone": (),
    "continue": ("threadId",), "next": ("granularity",), "stepIn": ("granularity",),
    "pause": (), "restart": (), "threads": (), "stackTrace": ("threadId",),
    "scopes": ("frameId",), "variables": ("variablesReference",),
    "exceptionInfo": ("threadId",), "evaluate": ("expression", "context")}
breakpoint_lists = st.lists(st.dictionaries(st.sampled_from(("line", "condition", "name")),
                                            json_values), max_size=3)


def _requests(command: str) -> st.SearchStrategy[tuple[str, Any]]:
    keys = st.sampled_from(KEYS[command]) if KEYS[command] else st.just("other")
    values = breakpoint_lists | json_values if "breakpoints" in KEYS[command] else json_values
    return st.tuples(st.just(command), json_values | st.dictionaries(keys, values,
                                                                     max_size=3))


@settings(max_examples=300)
@given(st.lists(st.sampled_from(tuple(KEYS)).flatmap(_requests), max_size=12))
def test_any_arguments_get_one_answer_and_never_break_the_adapter(
        requests: list[tuple[str, Any]]) -> None:
    sent: list[dict[str, Any]] = []
    adapter = Adapter(sent.append)
    launch = {"seq": 1, "type": "request", "command": "launch",
              "arguments": {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS),
                            "stopOnEntry": True}}
    adapter.receive(json.dumps(launch).encode())
    for seq, (command, arguments) in enumerate(requests, start=2):
        if adapter._worker is not None:
            adapter._worker.join(TIMEOUT)  # a run started by the request before
        adapter.receive(json.dumps({"seq": seq, "type": "request", "command": command,
                                    "arguments": arguments}).encode())
    responses = [m for m in sent if m["type"] == "response"]
    assert [m["request_seq"] for m in responses] == list(range(1, len(requests) + 2))
    assert not [m for m in responses if "please report it" in m.get("message", "")]


def test_a_request_sent_as_soon_as_the_run_stops_is_answered(tmp_path: Path) -> None:
    # The client hears of the stop from the worker, which is still ending: a request sent
    # at once, from the adapter's reading thread, was refused as `the program is running`
    # (at random, as threads ran). It waits until the stop is told whole, then is let in.
    program = tmp_path / "loop.rob"
    program.write_text(":10 A=A+1\n#10\n")
    idle: list[bool] = []
    asking = threading.Event()

    def ask() -> None:  # the reading thread's next request, as the client sends it
        asking.set()
        try:
            adapter._idle()
            idle.append(True)
        except Refused:
            idle.append(False)

    requests: list[threading.Thread] = []

    def send(message: dict[str, Any]) -> None:
        if message.get("event") == "stopped" and not requests:  # in the worker
            requests.append(threading.Thread(target=ask))
            requests[0].start()
            asking.wait(TIMEOUT)

    adapter = Adapter(send)
    for seq, (command, arguments) in enumerate(
            [("launch", {"program": str(program), "budget": 50}), ("configurationDone", {})],
            start=1):
        adapter.receive(json.dumps({"seq": seq, "type": "request", "command": command,
                                    "arguments": arguments}).encode())
    assert adapter._worker is not None
    adapter._worker.join(TIMEOUT)
    requests[0].join(TIMEOUT)
    assert idle == [True]


def test_the_command_line_answers_help_and_version_without_serving() -> None:
    for flag, said in (("--help", "Debug Adapter Protocol"), ("--version", "rl1-dap, version")):
        done = subprocess.run([sys.executable, "-m", "rl1.lsp.dap", flag], input=b"",
                              capture_output=True, timeout=60, check=False)
        assert done.returncode == 0 and said in done.stdout.decode(), done


class InProcess:
    """An adapter in this process, driven request by request; every message it sends
    kept."""

    def __init__(self) -> None:
        self.sent: list[dict[str, Any]] = []
        self.adapter = Adapter(self.sent.append)
        self.seq = 0

    def request(self, command: str, arguments: dict[str, Any] | None = None
                ) -> dict[str, Any]:
        """The response to the request, which the adapter sends before it returns."""
        self.seq += 1
        self.adapter.receive(json.dumps({"seq": self.seq, "type": "request",
                                         "command": command,
                                         "arguments": arguments or {}}).encode())
        (response,) = [m for m in self.sent
                       if m["type"] == "response" and m["request_seq"] == self.seq]
        return response

    def stopped_on(self) -> tuple[str, int]:
        """Why the run started by the last request stopped, and on which line."""
        if (running := self.adapter._worker) is not None:
            running.join(TIMEOUT)
        (stop,) = [m for m in self.sent if m.get("event") == "stopped"][-1:]
        return stop["body"]["reason"], self.request("stackTrace")["body"]["stackFrames"][0][
            "line"]


def _answer_in_process(request: dict[str, Any]) -> dict[str, Any]:
    """The response of a fresh adapter to `request`, which must come within seconds."""
    sent: list[dict[str, Any]] = []
    adapter = Adapter(sent.append)
    reading = threading.Thread(target=adapter.receive, args=(json.dumps(request).encode(),),
                               daemon=True)
    reading.start()
    reading.join(10)
    assert not reading.is_alive(), f"the adapter hangs on {request}"
    (response,) = [m for m in sent if m["type"] == "response"]
    return response


@pytest.mark.parametrize("arguments, said", [
    ({"program": "\ud800.rob"}, "is no file's path"),
    ({"program": "a\x00b.rob"}, "is no file's path"),
    ({"program": str(SAMPLE), "world": "w\ud800.world.toml"}, "is no file's path"),
    ({"program": str(SAMPLE), "sensors": "s\x00.sensors.json"}, "is no file's path"),
    ({"program": "/dev/null"}, "is a character device"),
    ({"program": str(SAMPLE), "world": "/dev/zero"}, "is a character device"),
])
def test_a_path_that_names_no_file_is_refused_with_why(arguments: dict[str, Any],
                                                       said: str) -> None:
    """Found by the hostile pass: each was an internal error ("please report it")."""
    response = _answer_in_process({"seq": 1, "type": "request", "command": "launch",
                                   "arguments": arguments})
    assert response["success"] is False and said in response["message"], response
    assert "please report it" not in response["message"]


def test_a_fifo_is_refused_not_waited_on(tmp_path: Path) -> None:
    """Found by the hostile pass: opening a FIFO waits for a writer, and the adapter,
    which reads its client's requests in the same thread, stopped answering."""
    for name, key in (("program.rob", "program"), ("w.world.toml", "world"),
                      ("s.sensors.json", "sensors")):
        fifo = tmp_path / name
        os.mkfifo(fifo)
        arguments = {"program": str(SAMPLE), key: str(fifo)}
        response = _answer_in_process({"seq": 1, "type": "request", "command": "launch",
                                       "arguments": arguments})
        assert response["message"] == f"{fifo}: it is a FIFO, not a regular file: name one"


@pytest.mark.parametrize("command", [5, None, ["threads"]])
def test_a_request_whose_command_is_no_string_is_answered(command: object) -> None:
    """Found by the hostile pass: skipped, it left its client waiting for an answer."""
    response = _answer_in_process({"seq": 7, "type": "request", "command": command})
    assert (response["request_seq"], response["success"]) == (7, False)
    assert response["message"] == ("a request's `command` is a string, such as "
                                   "\"launch\": send one")


def test_a_launch_while_the_program_runs_is_refused(tmp_path: Path) -> None:
    """Found by the hostile pass: the new launch replaced the session while the old
    program went on running in its worker, for good, and told its stops as the new
    one's."""
    looping = tmp_path / "loop.rob"
    looping.write_text(":01 A=A+1; #01\n")
    client = InProcess()
    client.request("launch", {"program": str(looping), "budget": 10**12})
    client.request("configurationDone")
    running = client.adapter._worker
    again = client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)})
    assert (again["success"], again["message"]) == (False, "the program is running: pause "
                                                           "it first")
    client.request("pause")
    assert running is not None
    running.join(TIMEOUT)
    assert not running.is_alive()
    assert client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)}
                          )["success"]


@pytest.mark.parametrize("seed", [-1, 2**32, 2**70])
def test_a_seed_outside_rl1c_sims_range_is_refused(seed: int) -> None:
    """Found by the hostile pass: a negative seed was an internal error ("please report
    it"), which the world's random generators raised."""
    response = _answer_in_process({"seq": 1, "type": "request", "command": "launch",
                                   "arguments": {"program": str(SAMPLE), "world": str(WORLD),
                                                 "seed": seed}})
    assert (response["success"], response["message"]) == (
        False, f"`seed` is {seed}: give a whole number from 0 to 4294967295, as rl1c sim "
               "--seed")


@pytest.mark.parametrize("elsewhere", ["other.rob", "missing.rob", "folder"])
def test_breakpoints_of_another_file_leave_the_programs_alone(tmp_path: Path,
                                                              elsewhere: str) -> None:
    """Found by the hostile pass: the adapter took every file's breakpoints for the
    program's, so that a client with breakpoints in two files (VS Code sends them file
    by file) had the second file's replace the program's, and stop on their lines."""
    (tmp_path / "other.rob").write_text("A=1\n")
    (tmp_path / "folder").mkdir()
    client = InProcess()
    client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)})
    ours = client.request("setBreakpoints", {"source": {"path": str(SAMPLE)},
                                             "breakpoints": [{"line": 20}]})
    assert ours["body"]["breakpoints"] == [{"verified": True, "line": 20}]
    other = client.request("setBreakpoints", {"source": {"path": str(tmp_path / elsewhere)},
                                              "breakpoints": [{"line": 1}, {"line": 3}]})
    said = (f"{tmp_path / elsewhere} is not the program being debugged, {SAMPLE.resolve()}: "
            "rl1-dap debugs one program")
    assert other["body"]["breakpoints"] == [{"verified": False, "line": line, "message": said}
                                            for line in (1, 3)]
    client.request("configurationDone")
    assert client.stopped_on() == ("breakpoint", 20)


@pytest.mark.parametrize("source", [3, "sample.rob", {"path": 5}])
def test_breakpoints_of_no_file_are_refused(source: object) -> None:
    client = InProcess()
    client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)})
    response = client.request("setBreakpoints", {"source": source, "breakpoints": []})
    assert (response["success"], response["message"]) == (
        False, f"`source` is {source!r}: give an object with the file's `path`")


@pytest.mark.parametrize(("command", "arguments", "said"), [
    ("stackTrace", {"threadId": 2}, "no thread has the id 2: the program's is 1"),
    ("continue", {"threadId": 0}, "no thread has the id 0: the program's is 1"),
    ("next", {"threadId": "1"}, "no thread has the id '1': the program's is 1"),
    ("pause", {"threadId": None}, "no thread has the id None: the program's is 1"),
    ("scopes", {"frameId": 7}, "no frame has the id 7: the program's line is frame 1"),
    ("evaluate", {"expression": "A", "frameId": 2},
     "no frame has the id 2: the program's line is frame 1"),
])
def test_a_thread_or_frame_never_given_out_is_refused(command: str, arguments: dict[str, Any],
                                                      said: str) -> None:
    """Found by the hostile pass: each was answered as if the id were the program's."""
    client = InProcess()
    client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS),
                              "stopOnEntry": True})
    client.request("configurationDone")
    response = client.request(command, arguments)
    assert (response["success"], response["message"]) == (False, said)
    assert client.request(command, {**arguments, "threadId": 1, "frameId": 1})["success"]


def test_conditions_are_read_without_holding_the_adapter() -> None:
    """Found by the hostile pass: a condition's two patterns backtracked over a run of
    spaces in time quadratic in its length, and the adapter, which reads requests in
    the thread that parses conditions, stopped answering: 2,000 conditions of 1,000
    characters some 50 s (a message's 64 MiB of one, hours)."""
    client = InProcess()
    client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)})
    wanted = [{"line": 20, "condition": f"A{' ' * 990}x{number}"} for number in range(2000)]
    answers: list[dict[str, Any]] = []
    setting = threading.Thread(target=lambda: answers.append(client.request(
        "setBreakpoints", {"breakpoints": wanted})), daemon=True)
    setting.start()
    setting.join(10)
    assert not setting.is_alive(), "the adapter hangs on the conditions"
    bindings = answers[0]["body"]["breakpoints"]
    assert [binding["verified"] for binding in bindings] == [False] * len(wanted)
    assert bindings[0]["message"].startswith("the condition `A ")


@pytest.mark.parametrize(("command", "arguments", "said"), [
    ("evaluate", {"expression": "A" * 1001},
     "`expression` is longer than 1,000 characters: give a value such as `U-L`"),
    ("setBreakpoints", {"breakpoints": [{"line": 20, "condition": "A" * 1001}]},
     "`breakpoints` is a list of objects, each with a `line` (1 or more) and maybe a "
     "`condition` of 1,000 characters at most"),
    ("setFunctionBreakpoints", {"breakpoints": [{"name": "IMG" + " " * 1000}]},
     "a function breakpoint's `name` is a built-in's: give a mnemonic of Table 2 or 3, as "
     "`IMG`, or a form, as `CAM P`"),
    ("setFunctionBreakpoints", {"breakpoints": [{"name": ["IMG"] * 1000}]},
     "a function breakpoint's `name` is a built-in's: give a mnemonic of Table 2 or 3, as "
     "`IMG`, or a form, as `CAM P`"),
])
def test_a_value_or_name_past_the_bound_is_refused_not_quoted(
        command: str, arguments: dict[str, Any], said: str) -> None:
    """Found by the hostile pass: each was quoted whole in its refusal, so that 64 MiB
    of it made an answer of up to six times that (JSON's escapes)."""
    client = InProcess()
    client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)})
    response = client.request(command, arguments)
    assert response.get("message", said) == said
    assert [b["message"] for b in response.get("body", {}).get("breakpoints", [])] in (
        [], [said])


LONG = "\u00e9" * 2**20  # 6 MiB of JSON escapes once quoted whole


@pytest.mark.parametrize(("command", "arguments"), [
    (LONG, {}),
    ("launch", {"program": LONG}),
    ("launch", {"program": str(SAMPLE), "sensors": LONG}),
    ("launch", {"program": str(SAMPLE), "world": LONG}),
    ("launch", {"program": [LONG]}),
    ("launch", {"program": str(SAMPLE), "budget": LONG}),
    ("launch", {"program": str(SAMPLE), "level": LONG}),
    ("launch", {"program": str(SAMPLE), "world": str(WORLD), "seed": LONG}),
    ("setBreakpoints", {"breakpoints": LONG}),
    ("setBreakpoints", {"source": {"path": LONG}, "breakpoints": [{"line": 1}]}),
    ("setBreakpoints", {"source": LONG, "breakpoints": []}),
    ("variables", {"variablesReference": LONG}),
    ("stackTrace", {"threadId": LONG}),
])
def test_a_refusal_quotes_an_excerpt_of_what_the_client_sent(command: str,
                                                             arguments: dict[str, Any]) -> None:
    """Found by the hostile pass: each refusal quoted the client's value whole, and
    JSON's escapes made 9 Mi characters of it an answer of 54 MiB."""
    client = InProcess()
    client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)})
    response = client.request(command, arguments)
    said = response.get("message") or response["body"]["breakpoints"][0]["message"]
    assert len(said) < 400, said[:200]
    # the whole answer too: a response names its request's command (an excerpt of it)
    assert len(json.dumps(response)) < 2000, json.dumps(response)[:200]


@pytest.mark.parametrize("first", ["configurationDone", "continue", "restart"])
def test_a_configuration_done_after_the_run_started_is_refused(tmp_path: Path,
                                                               first: str) -> None:
    """Found by the hostile pass: each configurationDone started the run again, in a
    worker of its own, beside the one a configurationDone, continue or restart had
    started: two threads stepped one machine."""
    looping = tmp_path / "loop.rob"
    looping.write_text(":01 A=A+1; #01\n")
    client = InProcess()
    client.request("launch", {"program": str(looping), "budget": 10**12})
    assert client.request(first)["success"]
    running = client.adapter._worker
    again = client.request("configurationDone")
    assert (again["success"], again["message"]) == (
        False, "the run has started: configurationDone comes once, after launch")
    assert client.adapter._worker is running
    client.request("pause")
    assert client.stopped_on()[0] == "pause"


def test_a_second_launch_tells_its_own_run_whole() -> None:
    """Found by the hostile pass: a launch after a run kept the run's count of the calls
    told, and its last stop, so that the new run's first calls were never told (as many
    as the run before had made) and exceptionInfo spoke of the old run's fault."""
    told: list[list[str]] = []
    client = InProcess()
    for _ in range(2):
        client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)})
        client.request("configurationDone")
        client.adapter._worker.join(TIMEOUT)  # type: ignore[union-attr]
        told.append([m["body"]["output"] for m in client.sent if m.get("event") == "output"])
        client.sent.clear()
    assert told[0] and told[1] == told[0]


def test_a_run_that_fails_ends_the_session_saying_so(monkeypatch: pytest.MonkeyPatch,
                                                     capsys: pytest.CaptureFixture[str]
                                                     ) -> None:
    """A bug of ours in a run (here one planted) printed a traceback from its worker
    thread and told the client nothing, which waited for a stop for good."""
    def failing(session: Session) -> Stop:
        raise RuntimeError("planted")

    monkeypatch.setattr(Session, "continue_", failing)
    client = InProcess()
    client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)})
    client.request("configurationDone")
    client.adapter._worker.join(TIMEOUT)  # type: ignore[union-attr]
    events = [m for m in client.sent if m["type"] == "event"]
    assert [m["event"] for m in events][-2:] == ["output", "terminated"]
    assert events[-2]["body"] == {"category": "stderr", "output": (
        "rl1-dap failed running the program (RuntimeError('planted')): please report it\n")}
    assert capsys.readouterr().err == ("rl1-dap: internal error in the run: "
                                       "RuntimeError('planted'); please report it\n")


@pytest.mark.parametrize("line", [0, -5])
def test_a_breakpoint_on_no_line_is_refused(line: int) -> None:
    """Found by the hostile pass: a line before the first (lines start at 1) was bound
    to the program's first line with code, and answered verified there."""
    client = InProcess()
    client.request("launch", {"program": str(SAMPLE), "sensors": str(SAMPLE_SENSORS)})
    response = client.request("setBreakpoints", {"breakpoints": [{"line": line}]})
    assert (response["success"], response["message"]) == (
        False, "`breakpoints` is a list of objects, each with a `line` (1 or more) and "
               "maybe a `condition` of 1,000 characters at most")
