"""The studio's protocol driven as the page drives it (spec/studio.md, "/studio"): Listing
1 launched on its world, stopped at a breakpoint with its variables, stepped, and run on
to the same ending as `rl1c sim`; frames while it runs; pause, restart, stop; the files;
and every kind of bad message answered with its JSON-RPC error, the server going on."""

from __future__ import annotations

import contextlib
import itertools
import json
import time
from pathlib import Path
from typing import Any

import pytest
from listing_1 import listing_1_folder, listing_1_page, listing_1_served  # noqa: F401  (fixtures)
from served import LISTING_1, Failed, Page, Served, page, serving
from support.cli import rl1c
from websockets.exceptions import ConnectionClosed

from rl1.lsp.studio import connection
from rl1.lsp.studio.run import FRAMES_PER_SECOND
from rl1.vm.language import BUILTINS, VARIABLES


def rl1c_sim(folder: Path) -> dict[str, Any]:
    ran = rl1c("sim", folder / "sample.rob", "--world", folder / "sample.world.toml",
               "--format", "json")
    assert ran.exit_code == 0, ran.stderr
    document: dict[str, Any] = json.loads(ran.stdout)
    return document


def told(client: Page, stop: dict[str, Any]) -> list[dict[str, Any]]:
    """The trace told up to `stop`: in the frames before it (the client passed over
    them), then in it."""
    frames = [message["params"] for message in client.skipped
              if message["method"] == "run/frame"]
    client.skipped.clear()
    return [entry for message in (*frames, stop) for entry in message["trace"]]


def test_initialize_names_the_folder_and_the_command_lines_files(client: Page,
                                                                  folder: Path) -> None:
    hello = client.request("initialize")
    assert hello["folder"] == str(folder.resolve())
    assert hello["rootUri"] == folder.resolve().as_uri()
    assert (hello["program"], hello["world"]) == ("sample.rob", "sample.world.toml")
    assert hello["maxFramesPerSecond"] == FRAMES_PER_SECOND


def test_listing_1_stops_at_line_20_steps_and_ends_as_rl1c_sim_does(client: Page,
                                                                    folder: Path) -> None:
    assert client.request("debug/setBreakpoints", {"lines": [{"line": 20}]}) == {
        "breakpoints": None, "calls": None}
    launched = client.request("run/launch", {**LISTING_1, "speed": None})
    assert launched["breakpoints"] == [
        {"line": 20, "boundTo": 20, "condition": None, "verified": True}]
    assert 20 in launched["lines"] and 11 not in launched["lines"]  # `:13` has no code

    stopped = client.until("run/stopped")
    assert (stopped["reason"], stopped["line"]) == ("breakpoint", 20)
    assert list(stopped["variables"]) == list(VARIABLES)
    # Lines 13-19 centred the camera on the stand: C is the pan; @ counted down from 5
    # to 0, where it started, so it is not changed.
    assert stopped["variables"]["@"] == 0
    assert {"C", "D", "L", "U"} <= set(stopped["changed"])
    assert "@" not in stopped["changed"]
    assert all(stopped["variables"][name] == 0 for name in VARIABLES
               if name not in stopped["changed"])
    assert stopped["frame"]["pan"] == stopped["variables"]["C"]
    assert stopped["device"]["camera pan (pulses)"] == stopped["variables"]["C"]
    before = told(client, stopped)
    assert [entry["call"] for entry in before[:3]] == ["CAM Z", "CAM A", "CAM D"]
    assert before[1]["text"] == "(CAM A 90)"

    client.request("debug/stepLine")
    stepped = client.until("run/stopped")
    assert (stepped["reason"], stepped["line"]) == ("step", 21)
    assert [entry["call"] for entry in stepped["trace"]] == ["STX", "MOV"]
    assert all(entry["line"] == 20 for entry in stepped["trace"])

    client.request("debug/setBreakpoints", {"lines": []})
    client.request("debug/continue")
    ended = client.until("run/ended")
    expected = rl1c_sim(folder)
    assert ended["status"] == expected["status"]
    assert ended["variables"] == expected["variables"]
    assert ended["instructions"] == expected["instructions"]
    assert ended["deviceTime"] == expected["device_time"]
    assert ended["goal"] == expected["goal"]
    trace = [*before, *stepped["trace"], *told(client, ended)]
    assert [{key: value for key, value in entry.items() if key != "text"}
            for entry in trace] == expected["trace"]


def test_frames_dropped_for_a_page_behind_lose_no_trace_entry(
        client: Page, folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # A frame dropped for the backlog took its trace entries and events with it.
    monkeypatch.setattr(connection, "FRAME_BACKLOG", -1)  # the page always behind
    client.request("debug/setBreakpoints", {"lines": [], "calls": []})
    client.request("run/launch", {**LISTING_1, "speed": None})
    ended = client.until("run/ended")
    assert not [message for message in client.skipped if message["method"] == "run/frame"]
    expected = rl1c_sim(folder)
    assert [{key: value for key, value in entry.items() if key != "text"}
            for entry in ended["trace"]] == expected["trace"]
    assert ended["image"] is not None  # the last (IMG)'s, whichever frame carried it


def test_stop_on_entry_then_step_an_instruction(client: Page) -> None:
    client.request("run/launch", {**LISTING_1, "stopOnEntry": True})
    entry = client.until("run/stopped")
    assert (entry["reason"], entry["line"], entry["changed"]) == ("entry", 2, [])
    assert entry["trace"] == []
    client.request("debug/stepInstruction")
    assert client.until("run/stopped")["reason"] == "step"
    assert client.request("debug/evaluate", {"expression": "C-1"}) == {"value": -1}


def test_a_conditional_breakpoint_and_a_call_breakpoint(client: Page) -> None:
    bound = client.request("debug/setBreakpoints", {
        "lines": [{"line": 15, "condition": "@-3<0"}, {"line": 16, "condition": "a<3"}],
        "calls": ["img", "CAM Q"]})
    assert bound["breakpoints"] is None
    launched = client.request("run/launch", {**LISTING_1, "speed": None})
    wrong, = (binding for binding in launched["breakpoints"] if not binding["verified"])
    assert wrong["line"] == 16 and "write `a-3<0`" in wrong["message"]
    assert launched["calls"][0] == {"name": "img", "verified": True}
    assert launched["calls"][1]["verified"] is False
    assert "its forms are" in launched["calls"][1]["message"]
    first = client.until("run/stopped")
    assert (first["reason"], first["text"]) == ("call", "(IMG)")
    client.request("debug/setBreakpoints", {"calls": []})
    client.request("debug/continue")
    second = client.until("run/stopped", "run/ended")
    # @ counts the centring steps down from 5 (line 13), one a pass (line 19).
    assert (second["reason"], second["line"], second["text"]) == ("breakpoint", 15, "@-3<0")
    assert second["variables"]["@"] == 2
    assert client.request("debug/evaluate", {"expression": "@-3"}) == {"value": -1}


def test_frames_come_while_it_runs_and_pause_stops_it(client: Page) -> None:
    client.request("debug/setBreakpoints", {"lines": [], "calls": []})
    started = time.monotonic()
    client.request("run/launch", {**LISTING_1, "speed": 10})
    frames = [client.until("run/frame") for _ in range(5)]
    client.request("debug/pause")
    paused = client.until("run/stopped")
    elapsed = time.monotonic() - started
    assert paused["reason"] == "pause"
    times = [frame["frame"]["time"] for frame in frames]
    assert times == sorted(times) and times[-1] > times[0]
    # At most FRAMES_PER_SECOND frames a second of wall time, however fast it runs.
    assert len(frames) <= FRAMES_PER_SECOND * elapsed + 1
    # At ten times real time, the simulated time is at most ten times the wall time.
    assert paused["frame"]["time"] <= 10 * elapsed + 0.1
    with pytest.raises(Failed) as running:
        client.request("debug/evaluate", {"expression": "A"})
        client.request("debug/continue", {"speed": None})
        client.request("debug/continue")
    assert running.value.code == -32006


def test_pausing_and_going_on_anywhere_changes_nothing(client: Page, folder: Path) -> None:
    client.request("debug/setBreakpoints", {"lines": [], "calls": []})
    client.request("run/launch", {**LISTING_1, "speed": 100})
    pauses = 0
    for delay in itertools.cycle([0.0, 0.01, 0.003, 0.05, 0.0, 0.02]):
        time.sleep(delay)
        client.request("debug/pause")
        stop = client.until("run/stopped", "run/ended")
        if stop["method"] == "run/ended":
            break
        pauses += 1
        client.request(["debug/continue", "debug/stepLine", "debug/stepInstruction"][
            pauses % 3])
        if pauses % 3:  # a step: it stops by itself, then the run goes on
            client.until("run/stopped")
            client.request("debug/continue")
    expected = rl1c_sim(folder)
    assert pauses > 3
    assert (stop["status"], stop["variables"], stop["instructions"], stop["deviceTime"]) == (
        expected["status"], expected["variables"], expected["instructions"],
        expected["device_time"])


def test_restart_starts_again_and_stop_ends_the_run(client: Page) -> None:
    client.request("debug/setBreakpoints", {"lines": [{"line": 6}], "calls": []})
    client.request("run/launch", {**LISTING_1, "speed": None})
    assert client.until("run/stopped")["line"] == 6
    client.request("debug/stepLine")
    client.until("run/stopped")
    client.request("debug/restart")
    again = client.until("run/stopped")
    assert (again["reason"], again["line"]) == ("breakpoint", 6)
    assert told(client, again)[0]["text"] == "(CAM Z)"  # told again from the start
    client.request("debug/stop")
    assert client.until("run/ended")["status"] is None
    with pytest.raises(Failed) as gone:
        client.request("debug/continue")
    assert gone.value.code == -32005


def test_a_sensor_script_runs_as_rl1c_run_does(client: Page, folder: Path) -> None:
    client.request("debug/setBreakpoints", {"lines": [], "calls": []})
    client.request("run/launch", {"program": {"path": "sample.rob"},
                                  "sensors": {"path": "sample.sensors.json"}})
    ended = client.until("run/ended")
    ran = rl1c("run", folder / "sample.rob", "--sensors", folder / "sample.sensors.json",
               "--format", "json")
    expected = json.loads(ran.stdout)
    assert ended["status"] == expected["status"]
    assert ended["variables"] == expected["variables"]
    assert ended["frame"] is None


def test_the_editors_text_runs_unsaved(client: Page) -> None:
    client.request("run/launch", {"program": {"text": "A=3\nB=A+A\n(END)\n", "name": "x.rob"}})
    assert client.until("run/ended")["variables"]["B"] == 6


def test_a_program_with_errors_is_not_launched(client: Page) -> None:
    with pytest.raises(Failed) as refused:
        client.request("run/launch", {"program": {"text": "A=(FOO)\n(END)\n"}})
    assert refused.value.code == -32003
    assert "program.rob:1: `FOO` is not a built-in function" in str(refused.value)
    diagnostic, = refused.value.data["diagnostics"]
    assert (diagnostic["file"], diagnostic["line"], diagnostic["code"]) == (
        "program.rob", 1, "E0501")


def test_a_broken_world_is_not_launched_and_says_where(client: Page) -> None:
    with pytest.raises(Failed) as refused:
        client.request("run/launch", {"program": {"path": "sample.rob"}, "world": {
            "text": "[floor]\nsize = [800, 500]\n[start]\nx = 'left'\ny = 1\n",
            "name": "w.world.toml"}})
    assert refused.value.code == -32004
    problem, = refused.value.data["errors"]
    assert problem["line"] == 4
    assert problem["message"].startswith("w.world.toml:4: start.x: ")


def test_world_check_gives_the_geometry_or_the_errors(client: Page, folder: Path) -> None:
    text = (folder / "sample.world.toml").read_text()
    checked = client.request("world/check", {"text": text, "path": "sample.world.toml"})
    assert checked["errors"] == []
    geometry = checked["geometry"]
    assert geometry["floor"] == [800, 500] and geometry["start"] == [60, 150, 0]
    assert [line["name"] for line in geometry["lines"]] == ["guide", "return"]
    stand, = geometry["stands"]
    assert stand["name"] == "stand" and len(stand["corners"]) == 4
    assert geometry["goal"]["holds"][0]["within"] == 60
    broken = client.request("world/check", {"text": text.replace("size = [800, 500]",
                                                                 "size = [800]")})
    assert broken["geometry"] is None
    assert broken["errors"][0]["line"] == 7
    assert broken["errors"][0]["message"].startswith("world.toml:7: floor.size")


def test_the_palette_is_vm_languages_builtins(client: Page) -> None:
    builtins = client.request("palette")["builtins"]
    assert [builtin["mnemonic"] for builtin in builtins] == list(BUILTINS)
    move = next(builtin for builtin in builtins if builtin["mnemonic"] == "MVI")
    form, = move["forms"]
    assert form["snippet"] == "(MVI ${1:l},${2:r},${3:cm})"
    assert form["params"][2] == {"name": "cm", "low": -1900, "high": 1900,
                                 "meaning": "distance in cm"}
    camera = next(builtin for builtin in builtins if builtin["mnemonic"] == "CAM")
    assert [form["snippet"] for form in camera["forms"]][:2] == ["(CAM Z)", "(CAM U)"]


def test_files_are_listed_read_and_saved(client: Page, folder: Path) -> None:
    listed = client.request("files/list")
    assert [entry["path"] for entry in listed["files"]] == [
        "sample.rob", "sample.sensors.json", "sample.world.toml"]
    read = client.request("files/read", {"path": "sample.rob"})
    assert read["text"] == (folder / "sample.rob").read_text()
    assert read["encoding"] == "utf-8"
    text = "'ロボット\n(END)\n"  # a legacy comment
    saved = client.request("files/save", {"path": "new.rob", "text": text,
                                          "encoding": "cp932"})
    assert (saved["path"], saved["size"]) == ("new.rob", 16)
    assert (folder / "new.rob").read_bytes() == text.encode("cp932")
    assert client.request("files/read", {"path": "new.rob"})["encoding"] == "cp932"
    for params, code in [({"path": "../x.rob", "text": ""}, -32001),
                         ({"path": "x.txt", "text": ""}, -32001),
                         ({"path": "x.rob", "text": "😀", "encoding": "cp932"}, -32002),
                         ({"path": "x.rob"}, -32602)]:
        with pytest.raises(Failed) as refused:
            client.request("files/save", params)
        assert refused.value.code == code
    with pytest.raises(Failed) as missing:
        client.request("files/read", {"path": "nothing.rob"})
    assert missing.value.code == -32002


def test_a_save_over_a_file_changed_since_it_was_read_is_refused(client: Page,
                                                                  folder: Path) -> None:
    (folder / "edited.rob").write_text("(END)\n")
    read = client.request("files/read", {"path": "edited.rob"})
    saved = client.request("files/save", {"path": "edited.rob", "text": "A=1\n(END)\n",
                                          "version": read["version"]})
    assert saved["version"] == client.request("files/read", {"path": "edited.rob"})["version"]
    (folder / "edited.rob").write_text("B=2\n(END)\n")  # another editor saves it
    with pytest.raises(Failed) as changed:
        client.request("files/save", {"path": "edited.rob", "text": "C=3\n(END)\n",
                                      "version": saved["version"]})
    assert changed.value.code == -32007
    assert "read it again" in str(changed.value)
    assert (folder / "edited.rob").read_text() == "B=2\n(END)\n"
    (folder / "edited.rob").unlink()  # deleted meanwhile: not the version read either
    with pytest.raises(Failed) as gone:
        client.request("files/save", {"path": "edited.rob", "text": "C=3\n(END)\n",
                                      "version": saved["version"]})
    assert gone.value.code == -32007
    assert not (folder / "edited.rob").exists()


@pytest.mark.parametrize(("message", "code"), [
    ("{bad", -32700),
    ("[1, 2]", -32600),
    ('{"jsonrpc": "2.0", "method": "initialize"}', -32600),
    ('{"jsonrpc": "1.0", "id": 7, "method": "initialize"}', -32600),
    ('{"jsonrpc": "2.0", "id": 7, "method": 3}', -32600),
    ('{"jsonrpc": "2.0", "id": 7, "method": "run/fly", "params": {}}', -32601),
    ('{"jsonrpc": "2.0", "id": 7, "method": "palette", "params": [1]}', -32602),
    ('{"jsonrpc": "2.0", "id": 7, "method": "run/launch", "params": {}}', -32602),
    ('{"jsonrpc": "2.0", "id": 7, "method": "run/launch", "params": '
     '{"program": {"path": "sample.rob"}, "level": 3}}', -32602),
    ('{"jsonrpc": "2.0", "id": 7, "method": "run/launch", "params": '
     '{"program": {"path": "sample.rob"}, "level": 1.0}}', -32602),
    ('{"jsonrpc": "2.0", "id": 7, "method": "run/launch", "params": '
     '{"program": {"path": "sample.rob"}, "level": true}}', -32602),
    ('{"jsonrpc": "2.0", "id": 7, "method": "run/launch", "params": '
     '{"program": {"path": "sample.rob"}, "speed": 0}}', -32602),
    ('{"jsonrpc": "2.0", "id": 7, "method": "files/read", "params": {"path": "/etc/passwd"}}',
     -32001),
    ('{"jsonrpc": "2.0", "id": 7, "method": "debug/setBreakpoints", "params": '
     '{"lines": [{"line": "20"}]}}', -32602),
    ("[" * 100_000, -32700),
    (json.dumps({"jsonrpc": "2.0", "id": 7, "method": "debug/setBreakpoints",
                 "params": {"lines": [{"line": 1}] * 10_001}}), -32602),
    (json.dumps({"jsonrpc": "2.0", "id": 7, "method": "debug/setBreakpoints",
                 "params": {"lines": [{"line": 1, "condition": "A" * 1001 + "<0"}]}}), -32602),
    (json.dumps({"jsonrpc": "2.0", "id": 7, "method": "run/launch",
                 "params": {"program": {"text": "'" * (8 * 2**20 + 1)}}}), -32002),
])
def test_bad_messages_are_answered_and_the_server_goes_on(client: Page, message: str,
                                                          code: int) -> None:
    client.send(message)
    answer = client.answer(7 if '"id": 7' in message else None)
    assert answer["error"]["code"] == code
    assert answer["error"]["message"]
    assert client.request("initialize")["program"] == "sample.rob"


def test_commands_without_a_run_say_to_launch(served: Served) -> None:
    with page(served) as fresh:
        for method in ("debug/continue", "debug/stepLine", "debug/pause", "debug/stop"):
            with pytest.raises(Failed, match="run/launch") as refused:
                fresh.request(method)
            assert refused.value.code == -32005


@pytest.mark.parametrize("command", ["debug/pause", "debug/restart", "debug/stop"])
def test_a_long_call_at_real_time_does_not_hold_up_a_command(client: Page,
                                                            command: str) -> None:
    # (TIM 100) waits 10 s moving, which one instruction paced at a tenth of real time
    # makes 100 s: a command must not wait for its end (longer than TIMEOUT).
    client.request("debug/setBreakpoints", {"lines": [], "calls": []})
    client.request("run/launch", {"program": {"text": "(MOV 1,1)\n(TIM 100)\n(END)\n"},
                                  "world": {"path": "sample.world.toml"}, "speed": 0.1,
                                  "stopOnEntry": True})
    client.until("run/stopped")
    client.request("debug/continue")
    while (moving := client.until("run/frame")["frame"])["time"] < 0.01:
        pass  # until the (TIM) is under way (the instructions before take 0.2 ms each)
    client.request(command)
    stop = client.until("run/stopped", "run/ended")
    assert stop["method"] == {"debug/pause": "run/stopped", "debug/restart": "run/stopped",
                              "debug/stop": "run/ended"}[command]
    if command == "debug/pause":  # at the instruction after the call, as the VM stops
        assert (stop["reason"], stop["line"]) == ("pause", 3)
        assert stop["frame"]["time"] > moving["time"]
    if command == "debug/restart":
        assert (stop["reason"], stop["frame"]["time"]) == ("entry", 0)


def test_a_page_beyond_eight_is_told_to_close_one(folder: Path) -> None:
    with serving(folder) as served, contextlib.ExitStack() as pages:
        opened = [pages.enter_context(page(served)) for _ in range(8)]
        assert all(each.request("initialize") for each in opened)
        with page(served) as ninth, pytest.raises(ConnectionClosed) as closed:
            ninth.request("initialize")
        assert closed.value.rcvd is not None
        assert closed.value.rcvd.code == 1013
        assert "8 pages" in closed.value.rcvd.reason
        pages.close()
        # The places are given back once the server has seen the pages close.
        for _ in range(100):
            with page(served) as again, contextlib.suppress(ConnectionClosed):
                assert again.request("initialize")
                break
            time.sleep(0.05)
        else:
            raise AssertionError("no place was given back")
