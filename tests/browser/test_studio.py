"""The studio (`rl1c studio`, spec/studio.md) in a real browser: Debian's chromium driven
by Playwright for Python, as test_replay_page.py drives it (no browser of Playwright's
own). The studio serves a copy of examples/ with Listing 1 and its world; the page opens
with the token and shows a mistyped call's diagnostic and applies its quick fix; hover,
completion, signature help, go to definition, rename and formatting come from the
language server; the palette inserts a call with its arguments as fields; a breakpoint
on line 20 stops the vehicle there with the variables shown, a step and a continue run
to the end, and a conditional breakpoint stops where its condition holds; the world
file's error is shown as it is edited, and on a guidance line made shorter the lost line
and the handler jump are marked in the trace; saving writes the file; the page is usable
420 px wide; nothing is logged on its console. A screenshot of each step is kept in
build/studio-screenshots/."""

from __future__ import annotations

import contextlib
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from support import EXAMPLES, ROOT
from support.browser import WatchedPage, chromium, playwright_or_skip

RL1C = str(Path(sys.executable).with_name("rl1c"))
SCREENSHOTS = ROOT / "build" / "studio-screenshots"
SERVING = re.compile(r"rl1c studio: serving .* at (http://127\.0\.0\.1:\d+/\?token=\S+) ")
WAIT = 20_000  # ms: a step of the page on two shared cores
# The page's Content-Security-Policy allows no eval, so the tests wait for selectors
# (Playwright's wait_for_function evaluates a string).

sync_api = playwright_or_skip()


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A copy of examples/, which the studio serves."""
    copy = tmp_path_factory.mktemp("studio") / "examples"
    shutil.copytree(EXAMPLES, copy)
    return copy


@contextlib.contextmanager
def serving(folder: Path) -> Iterator[tuple[subprocess.Popen[str], str]]:
    """`rl1c studio` on Listing 1 and its world in `folder`, and the page's address."""
    with subprocess.Popen([RL1C, "studio", "sample.rob", "--world", "sample.world.toml",
                           "--no-browser", "--port", "0"], cwd=folder, text=True,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE) as server:
        assert server.stdout is not None
        first = server.stdout.readline()
        serving = SERVING.match(first)
        if serving is None:
            server.kill()
            pytest.fail(f"rl1c studio did not say where it serves: {first!r}"
                        f"{server.communicate(timeout=30)[1]}")
        yield server, serving[1]
        server.terminate()
        server.communicate(timeout=30)


@pytest.fixture(scope="module")
def studio(folder: Path) -> Iterator[str]:
    """The studio the tests share: the page's address."""
    with serving(folder) as (_, address):
        yield address


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with chromium(sync_api) as launched:
        yield launched


class Studio(WatchedPage):
    """The page open in a fresh context `width` pixels wide, once ready: what it asks of
    anywhere but the studio's server is `elsewhere`."""

    def __init__(self, browser: Any, address: str, width: int) -> None:
        origin = address.split("/?", 1)[0]  # http://127.0.0.1:PORT
        served = (origin, origin.replace("http", "ws", 1), "data:")
        super().__init__(browser, address, lambda url: url.startswith(served),
                         viewport={"width": width, "height": 900})
        self.page.wait_for_selector("body[data-ready=true]", state="attached", timeout=WAIT)

    def shot(self, name: str) -> None:
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        self.page.screenshot(path=str(SCREENSHOTS / f"{name}.png"), full_page=True)

    def line(self, number: int) -> Any:
        """The editor's line `number` (1-based), scrolled into view."""
        gutter = self.page.locator("#editor .cm-lineNumbers .cm-gutterElement", has_text=re.compile(
            f"^{number}$"))
        if gutter.count() == 0:  # not drawn: the editor draws the lines near its view
            self.page.locator("#editor .cm-scroller").evaluate(
                "(scroller, line) => { scroller.scrollTop = (line - 3) * "
                "scroller.querySelector('.cm-line').offsetHeight; }", number)
        gutter.scroll_into_view_if_needed()
        top = gutter.bounding_box()["y"]
        return next(line for line in self.page.locator("#editor .cm-line").all()
                    if abs(line.bounding_box()["y"] - top) < 2)

    def gutter(self, number: int, button: str = "left") -> None:
        """Clicks the breakpoints' gutter beside line `number`."""
        line = self.line(number).bounding_box()
        gutter = self.page.locator(".cm-breakpoint-gutter").bounding_box()
        self.page.mouse.click(gutter["x"] + gutter["width"] / 2,
                              line["y"] + line["height"] / 2, button=button)

    def stop(self, reason: str) -> str:
        self.page.wait_for_selector(f"#stop[data-reason='{reason}']", state="attached",
                                    timeout=WAIT)
        return self.page.text_content("#stop") or ""

    def vehicle(self) -> str:
        return self.page.get_attribute("#vehicle", "points") or ""


@pytest.fixture
def wide(browser: Any, studio: str) -> Iterator[Studio]:
    opened = Studio(browser, studio, 1400)
    yield opened
    assert opened.problems == [], "the page logged problems"
    assert opened.elsewhere == [], "the page asked for something besides the studio"
    opened.context.close()


def test_a_mistyped_call_shows_its_diagnostic_and_its_quick_fix_mends_it(wide: Studio) -> None:
    page = wide.page
    line = wide.line(3)
    original = line.text_content()
    assert original == "(SCN 0); (TRC 3); (MOV 3,3)"
    wide.shot("01-opened")
    assert page.locator(".cm-lintRange-error").count() == 0
    line.click()
    page.keyboard.press("End")
    for _ in range(len(" 3,3)")):
        page.keyboard.press("ArrowLeft")
    page.keyboard.press("Backspace")
    page.keyboard.type("B")  # (MOB 3,3)
    mark = page.locator(".cm-lintRange-error")
    mark.wait_for(timeout=WAIT)
    assert mark.text_content() == "MOB"
    mark.hover()
    fix = page.locator(".cm-tooltip-lint .cm-diagnosticAction")
    fix.wait_for(timeout=WAIT)
    tooltip = page.text_content(".cm-tooltip-lint") or ""
    assert "`MOB` is not a built-in function" in tooltip
    assert fix.text_content() == "write `MOV`"
    wide.shot("02-diagnostic")
    fix.click()
    assert wide.line(3).text_content() == original
    page.locator(".cm-lintRange-error").first.wait_for(state="detached", timeout=WAIT)
    wide.shot("03-quick-fix-applied")


def test_hover_completion_signature_definition_and_rename(wide: Studio) -> None:
    page = wide.page
    wide.line(3).locator("span", has_text=re.compile("^MOV$")).hover()
    hover = page.locator(".cm-tooltip-hover")
    hover.wait_for(timeout=WAIT)
    assert "Start moving at the given wheel speeds" in (hover.text_content() or "")
    page.mouse.move(0, 0)
    wide.line(11).click()  # :13
    page.keyboard.press("End")
    page.keyboard.type(" (IM")
    completion = page.locator(".cm-tooltip-autocomplete")
    completion.wait_for(timeout=WAIT)
    assert "IMG" in (completion.text_content() or "")
    page.keyboard.press("Escape")
    for _ in range(len("IM")):
        page.keyboard.press("Backspace")
    page.keyboard.type("MOV ")
    signature = page.locator(".cm-lsp-signature-tooltip")
    signature.wait_for(timeout=WAIT)
    assert "(MOV l,r)" in (signature.text_content() or "")
    wide.shot("04-signature-help")
    page.keyboard.press("Escape")
    wide.line(19).locator("span", has_text=re.compile("^#14$")).click()  # @--; ?@>#14
    page.keyboard.press("F12")
    sync_api.expect(page.locator("#editor .cm-activeLine")).to_have_text(":14 (IMG)")
    page.keyboard.press("F2")
    name = page.locator(".cm-lsp-rename-panel input[name=name]")
    name.fill(":15")
    name.press("Enter")
    sync_api.expect(wide.line(14)).to_have_text(":15 (IMG)", timeout=WAIT)
    assert wide.line(19).text_content() == "@--; ?@>#15"


def test_the_palette_inserts_a_call_with_a_field_for_each_argument(wide: Studio) -> None:
    page = wide.page
    assert wide.line(11).text_content() == ":13"
    wide.line(11).click()
    page.keyboard.press("End")
    page.click("#palette button[title^='Move: ']")  # (MOV l,r), Table 2
    page.keyboard.type("2")  # the first field, l, is selected
    page.keyboard.press("Tab")
    page.keyboard.type("-2")
    assert wide.line(11).text_content() == ":13 (MOV 2,-2)"
    tables = page.locator("#palette .table").all_text_contents()
    assert tables == ["Table 2: motion", "Table 3: sensing"]
    calls = page.locator("#palette button").all_text_contents()
    assert "(CAM P pulse)" in calls and "(ULT A)" in calls and "(END)" not in calls
    wide.shot("05-palette")


def test_the_editor_highlights_rl1(wide: Studio) -> None:
    page = wide.page
    kinds = {text: wide.line(line).locator("span", has_text=re.compile(f"^{re.escape(text)}$"))
             .first.get_attribute("class") for line, text in (
                 (2, "CAM"), (2, "Z"), (4, ":10"), (4, "#10"), (4, "?"), (6, "x"), (8, "A"),
                 (9, "-450"), (41, ":96"), (1, "'SAMPLE.ROB"))}
    assert kinds == {"CAM": "tok-builtin", "Z": "tok-selector", ":10": "tok-label",
                     "#10": "tok-label", "?": "tok-keyword", "x": "tok-variable tok-reserved",
                     "A": "tok-variable", "-450": "tok-number", ":96": "tok-label tok-handler",
                     "'SAMPLE.ROB": "tok-comment"}
    assert page.locator("#palette button").count() > 20


def test_a_breakpoint_stops_the_vehicle_then_step_and_continue_to_the_end(wide: Studio) -> None:
    page = wide.page
    start = wide.vehicle()
    assert start, "the vehicle is drawn at its start"
    page.select_option("#speed", "10")
    assert wide.line(20).text_content() == "(STX D); (MOV 1,1)"
    wide.gutter(20)
    assert page.locator(".cm-breakpoint-dot").count() == 1
    page.click("#run")
    assert wide.stop("breakpoint") == "breakpoint at line 20"
    assert page.locator(".cm-run-line").text_content() == "(STX D); (MOV 1,1)"
    assert wide.vehicle() != start, "the vehicle moved to where line 20 runs"
    assert int(page.get_attribute("#world", "data-frames-drawn") or 0) > 1, "it moved live"
    assert page.locator("#variables .variable").count() == 53
    assert page.locator("#variables .variable.changed").count() > 0
    assert page.locator("#device dt", has_text="x (cm)").count() == 1
    wide.shot("06-stopped-at-the-breakpoint")

    page.click("#step-line")
    assert wide.stop("step") == "step at line 21"
    assert page.locator(".cm-run-line").text_content() == ":20 (IMG)"
    wide.shot("07-stepped")

    page.click("#continue")
    assert wide.stop("end").startswith("ended: the program ended; goal met; ")
    assert page.locator(".cm-run-line, .cm-fault-line").count() == 0
    assert "(IMG) = " in (page.text_content("#trace") or "")
    assert page.locator("#world .event.end").count() == 1
    wide.shot("08-ended")


def test_the_camera_pane_shows_the_image_img_saw_and_the_plots_its_readings(
        wide: Studio) -> None:
    page = wide.page
    page.select_option("#speed", "")  # as fast as the server runs
    wide.gutter(20)
    page.click("#run")
    assert wide.stop("breakpoint") == "breakpoint at line 20"
    page.wait_for_selector("#camera[data-time]", state="attached", timeout=WAIT)
    # Lines 13-19 centred the camera on the stand's two LEDs (scene 2): the last (IMG).
    reading = re.search(r"\(IMG\) at [0-9.]+ s in scene 2: area (\d+), x (\d+), y (\d+)",
                        page.text_content("#camera-caption") or "")
    assert reading is not None
    area, x, y = map(int, reading.groups())
    width, height, white, mean_x, mean_y = page.eval_on_selector("#camera", """camera => {
        const data = camera.getContext("2d").getImageData(0, 0, camera.width,
                                                           camera.height).data;
        let white = 0, sumX = 0, sumY = 0;
        for (let p = 0; p < data.length; p += 4) {
          if (data[p] === 255 && data[p + 1] === 255 && data[p + 2] === 255) {
            const i = p / 4;
            white++; sumX += i % camera.width; sumY += Math.floor(i / camera.width);
          }
        }
        return [camera.width, camera.height, white, sumX / white, sumY / white];
    }""")
    assert (width, height) == (256, 240)  # the world's image, pixel for pixel
    # The world has no noise: the white pixels are the area (IMG) read, less those the
    # centroid's cross covers (13 across, 13 down), and their centre is its x, y.
    assert area > 0 and area - 26 <= white <= area
    assert abs(mean_x - x) <= 1.5 and abs(mean_y - y) <= 1.5
    wheels = page.locator("#plots svg[data-name='wheel speeds'] polyline.series")
    assert [wheels.nth(i).get_attribute("data-name") for i in range(2)] == ["left", "right"]
    assert all(wheels.nth(i).get_attribute("points") for i in range(2)), "wheel speeds drawn"
    image = page.locator("#plots svg[data-name='IMG'] polyline.series")
    assert image.count() == 4 and (image.first.get_attribute("points") or "").count(",") > 2
    assert (page.text_content("#plots") or "").count("IMG: area ") == 1
    wide.shot("12-camera-and-plots")


def test_a_breakpoint_with_a_condition_stops_when_it_holds(wide: Studio) -> None:
    page = wide.page
    page.select_option("#speed", "")  # as fast as the server runs
    assert wide.line(22).text_content() == "      Y=y-160; ?Y>#29"
    page.once("dialog", lambda dialog: dialog.accept("y-160>0"))
    wide.gutter(22, button="right")
    assert page.locator(".cm-breakpoint-dot.conditional").count() == 1
    page.click("#run")
    assert wide.stop("breakpoint") == "breakpoint at line 22: y-160>0"
    y = int(page.text_content("#variables .variable[data-name=y] .value") or "0")
    assert y > 160
    page.once("dialog", lambda dialog: dialog.accept("y-"))  # not a value: refused
    wide.gutter(22, button="right")
    page.wait_for_selector("#status.problem", timeout=WAIT)
    assert (page.text_content("#status") or "").startswith("breakpoint on line 22: ")


def test_the_world_file_shows_its_error_and_a_shorter_line_is_lost(wide: Studio) -> None:
    page = wide.page
    world = (EXAMPLES / "sample.world.toml").read_text(encoding="utf-8")
    page.click("#world-file summary")
    page.click("#world-editor .cm-content")
    page.keyboard.press("Control+a")
    page.keyboard.insert_text(world.replace("size = [800, 500]", "size = [800, -5]"))
    problem = page.locator("#world-errors li")
    problem.wait_for(timeout=WAIT)
    assert (problem.text_content() or "").startswith("sample.world.toml:7: floor.size")
    assert page.locator("#world-editor .cm-lintRange-error").count() == 1
    wide.shot("09-world-file-error")
    # The guidance line ends before the branch mark: tracing in mode 3 loses it during
    # (MOV 3,3), and Listing 1 jumps to its handler :96.
    page.keyboard.press("Control+a")
    page.keyboard.insert_text(world.replace("[[0, 150], [800, 150]]", "[[0, 150], [200, 150]]"))
    problem.first.wait_for(state="detached", timeout=WAIT)
    page.select_option("#speed", "")  # as fast as the server runs
    page.click("#run")
    assert "goal missed" in wide.stop("goal-missed")
    assert "line lost during MOV in mode 3" in (page.text_content("#trace li.lost") or "")
    assert ":96" in (page.text_content("#trace li.handler") or "")
    assert page.locator("#world .event.lost").count() == 1
    wide.shot("10-line-lost")
    page.check("#stop-on-lost")
    page.click("#run")
    assert wide.stop("lost-line") == ("lost-line at line 41: line lost (mode 3, MOV): "
                                      "jump to :96")
    assert page.locator(".cm-run-line").text_content() == ":96 (MOV 0,0)"


def test_format_lays_the_program_out(wide: Studio) -> None:
    assert wide.line(9).text_content() == "      c=205; d=-450; #13"
    wide.page.click("#format")
    sync_api.expect(wide.line(9)).to_have_text("c=205; d=-450; #13", timeout=WAIT)


def test_saving_writes_the_file(wide: Studio, folder: Path) -> None:
    page = wide.page
    assert wide.line(43).text_content() == "(FRE); (END)"
    wide.line(43).click()
    page.keyboard.press("End")
    page.keyboard.type(" ' the end")
    assert "unsaved" in (page.get_attribute("#program-file", "class") or "")
    page.keyboard.press("Control+s")
    page.wait_for_selector("#status:text('saved sample.rob')", timeout=WAIT)
    assert (folder / "sample.rob").read_text(encoding="utf-8").endswith(
        "(FRE); (END) ' the end\n")
    assert "unsaved" not in (page.get_attribute("#program-file", "class") or "")


def test_at_420_px_the_panes_stack_and_stay_usable(browser: Any, studio: str) -> None:
    narrow = Studio(browser, studio, 420)
    page = narrow.page
    page.select_option("#speed", "")  # as fast as the server runs
    page.click("#run")
    page.wait_for_selector("body[data-run=ended]", state="attached", timeout=60_000)
    for selector in ("#program-file", "#save", "#run", "#step-line", "#continue", "#speed",
                     "#palette button", ".cm-content", "#world", "#stop", "#variables",
                     "#trace", *(f"#{pane}" for pane in page.eval_on_selector_all(
                         ".pane:not([hidden])", "panes => panes.map(pane => pane.id)") if pane)):
        element = page.locator(selector).first
        element.scroll_into_view_if_needed()
        assert element.is_visible(), selector
        box = element.bounding_box()
        assert box is not None and box["x"] >= 0 and box["x"] + box["width"] <= 420, selector
    assert page.evaluate("document.documentElement.scrollWidth") <= 420, "no sideways scrolling"
    tops = [page.locator(selector).bounding_box()["y"]
            for selector in ("#editor", "#world", "#stop", "#variables")]
    assert tops == sorted(tops), "the editor, the world, where it stopped, the variables"
    narrow.shot("11-at-420px")
    assert narrow.problems == []
    narrow.context.close()


def test_the_page_says_when_the_studio_is_gone(browser: Any, folder: Path) -> None:
    with serving(folder) as (server, address):
        gone = Studio(browser, address, 1400)
        server.terminate()
        server.communicate(timeout=30)
        sync_api.expect(gone.page.locator("#status.problem")).to_have_text(
            "disconnected: the studio's server closed the connection: start `rl1c studio` "
            "again", timeout=WAIT)
        gone.context.close()
