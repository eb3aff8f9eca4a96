"""The studio's camera pane and sensor plots as the protocol feeds them (spec/studio.md):
a stop or a frame after an (IMG) carries the binary image the simulator rendered
(CameraImage), exactly the replay page's frame of that sighting (vm/sim/render.py);
nothing when no (IMG) came since, so that an image is sent once; none on the scripted
device; and the palette names each value of a reading, for the plots."""

from __future__ import annotations

import base64
import json
from pathlib import Path
from typing import Any

import numpy as np
from listing_1 import listing_1_folder, listing_1_page, listing_1_served  # noqa: F401  (fixtures)
from served import LISTING_1, Page
from support.cli import rl1c


def replay_frames(folder: Path, into: Path) -> list[dict[str, Any]]:
    """The camera's frames of the page `rl1c sim --html` writes for Listing 1."""
    written = into / "replay.html"
    ran = rl1c("sim", folder / "sample.rob", "--world", folder / "sample.world.toml",
               "--html", written)
    assert ran.exit_code == 0, ran.stderr
    text = written.read_text(encoding="utf-8")
    frames: list[dict[str, Any]] = json.loads(
        text.split("const run = ", 1)[1].split(";\n", 1)[0])["frames"]
    return frames


def pixels_in_window(image: dict[str, Any]) -> int:
    """The set pixels of `image` inside its window: what (IMG) counts as the area."""
    bits = np.unpackbits(np.frombuffer(base64.b64decode(image["bits"]), dtype=np.uint8))
    rows, columns = image["rows"], image["columns"]
    assert len(bits) == (rows * columns + 7) // 8 * 8, "whole bytes, no more"
    shown = bits[:rows * columns].reshape(rows, columns).astype(bool)
    x0, y0, x1, y1 = image["window"]
    left, top = image["left"], image["top"]
    return int(shown[max(0, y0 - top):max(0, y1 - top), max(0, x0 - left):max(0, x1 - left)]
               .sum())


def made(entry: dict[str, Any], time: float) -> bool:
    """Whether the trace's `entry` is the (IMG) an image of `time` shows (the trace gives
    times to 0.1 ms, an image to 1 ms)."""
    return bool(entry["call"] == "IMG" and abs(entry["time"] - time) <= 0.0005 + 1e-9)


def test_the_first_img_sends_the_replay_pages_image(client: Page, folder: Path,
                                                     tmp_path: Path) -> None:
    client.request("debug/setBreakpoints", {"lines": [], "calls": ["IMG"]})
    client.request("run/launch", {**LISTING_1, "speed": None})
    before = client.until("run/stopped")  # before the first (IMG), line 4
    assert (before["reason"], before["line"], before["image"]) == ("call", 4, None)
    client.request("debug/continue")
    after = client.until("run/stopped")  # before the second: the first was made
    img, = (entry for entry in after["trace"] if entry["call"] == "IMG")
    image = after["image"]
    # The replay page's first frame is the run's first sighting, whatever their number.
    assert image == replay_frames(folder, tmp_path)[0]
    assert made(img, image["time"])
    assert image["reading"] == img["result"][:3]
    assert image["size"] == [256, 240] and image["reading"][0] > 0
    assert pixels_in_window(image) == image["reading"][0]  # the world has no noise

    client.request("debug/setBreakpoints", {"lines": [{"line": 5}], "calls": []})
    client.request("debug/continue")
    assert client.until("run/stopped")["image"]["time"] > image["time"]
    client.request("debug/stepLine")  # (MOV 0,0); (TRC 0): no (IMG), no image again
    assert client.until("run/stopped")["image"] is None


def test_an_image_is_sent_once_for_each_img_at_most_and_the_last_at_the_end(
        client: Page) -> None:
    client.request("debug/setBreakpoints", {"lines": [], "calls": []})
    client.request("run/launch", {**LISTING_1, "speed": 20})
    ended = client.until("run/ended")
    frames = [message["params"] for message in client.skipped
              if message["method"] == "run/frame"]
    imgs = [entry for notice in (*frames, ended) for entry in notice["trace"]
            if entry["call"] == "IMG"]
    assert len(imgs) > 50  # Listing 1 polls (IMG) while it drives to the stand
    # A frame carries an image only after a new (IMG): each sighting once, in order,
    # at a time an (IMG) was made.
    times = [frame["image"]["time"] for frame in frames if frame["image"] is not None]
    assert 0 < len(times) < len(frames) and len(times) <= len(imgs)
    assert times == sorted(set(times))
    assert all(any(made(entry, time) for entry in imgs) for time in times)
    # The end carries the last (IMG)'s image (a frame that carried it may have been
    # dropped for a page that fell behind).
    last = ended["image"]
    assert made(imgs[-1], last["time"]) and last["time"] >= times[-1]
    assert last["reading"] == imgs[-1]["result"][:3]
    assert pixels_in_window(last) == last["reading"][0]


def test_a_restart_sends_the_image_again(client: Page) -> None:
    client.request("debug/setBreakpoints", {"lines": [{"line": 20}], "calls": []})
    client.request("run/launch", {**LISTING_1, "speed": None})
    first = client.until("run/stopped")
    assert first["line"] == 20 and first["image"] is not None
    client.request("debug/restart")
    again = client.until("run/stopped")
    assert again["line"] == 20 and again["image"] == first["image"]


def test_the_scripted_device_sends_no_image(client: Page) -> None:
    client.request("debug/setBreakpoints", {"lines": [], "calls": []})
    client.request("run/launch", {"program": {"path": "sample.rob"},
                                  "sensors": {"path": "sample.sensors.json"}})
    ended = client.until("run/ended")
    assert any(entry["call"] == "IMG" for entry in ended["trace"])
    assert ended["image"] is None


def test_the_palette_names_each_value_of_a_reading_for_the_plots(client: Page) -> None:
    builtins = {builtin["mnemonic"]: builtin for builtin in client.request("palette")["builtins"]}
    assert builtins["IMG"]["readings"] == ["area", "x", "y", "angle"]
    assert builtins["KYO"]["readings"] == ["centre", "right", "left"]
    assert builtins["ULT"]["readings"] == builtins["MOV"]["readings"] == []
    client.request("debug/setBreakpoints", {"lines": [], "calls": []})
    client.request("run/launch", {**LISTING_1, "speed": None})
    ended = client.until("run/ended")
    trace = [entry for message in client.skipped if message["method"] == "run/frame"
             for entry in message["params"]["trace"]] + ended["trace"]
    # Every value of a reading of several has its name; a reading of one, its call's.
    for entry in trace:
        if "result" in entry:
            names = builtins[entry["call"].split()[0]]["readings"]
            assert len(entry["result"]) == (len(names) if names else 1), entry
