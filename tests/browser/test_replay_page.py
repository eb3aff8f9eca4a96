"""The replay page of `rl1c sim --html` in a real browser: Debian's chromium, driven by
Playwright for Python (tests/browser/install-chromium installs both; no browser of
Playwright's own is ever downloaded). The page opens from a file:// URL with the network
off, plays, pauses on Space, scrubs, and shows the log's lost line and handler, the
camera's image and the plots, with nothing on the console."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from support.browser import WatchedPage, chromium, playwright_or_skip
from support.pictures import HANDLER_LINE, draw

sync_api = playwright_or_skip()


@pytest.fixture(scope="module")
def replay(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return draw(tmp_path_factory.mktemp("replay"))[1]


@pytest.fixture(scope="module")
def browser() -> Iterator[object]:
    with chromium(sync_api) as launched:
        yield launched


class Page(WatchedPage):
    """The replay page open in a fresh offline context: what it asks for besides itself
    is `elsewhere`."""

    def __init__(self, browser: object, path: Path) -> None:
        address = path.as_uri()
        super().__init__(browser, address, lambda url: url.split("#")[0] == address,
                         offline=True)

    def clock(self) -> float:
        text = self.page.text_content("#clock") or ""
        match = re.fullmatch(r"([0-9.]+) s", text)
        assert match, text
        return float(match[1])

    def scrub(self, permille: int) -> None:
        self.page.eval_on_selector(
            "#scrub", "(slider, value) => { slider.value = value; "
            "slider.dispatchEvent(new Event('input')); }", permille)

    def vehicle(self) -> str:
        return self.page.get_attribute("#vehicle", "points") or ""


@pytest.fixture
def page(browser: object, replay: Path) -> Iterator[Page]:
    opened = Page(browser, replay)
    yield opened
    assert opened.problems == [], "the page logged problems"
    assert opened.elsewhere == [], "the page asked for something besides itself"
    opened.context.close()


def test_it_plays_and_space_pauses(page: Page) -> None:
    assert page.clock() == 0
    page.page.keyboard.press("Space")
    page.page.wait_for_function(
        "parseFloat(document.getElementById('clock').textContent) > 1")
    assert page.page.text_content("#play") == "Pause"
    page.page.keyboard.press("Space")
    assert page.page.text_content("#play") == "Play"
    paused = page.clock()
    page.page.wait_for_timeout(300)
    assert page.clock() == paused > 1


def test_the_play_button_and_the_speed_control(page: Page) -> None:
    page.page.select_option("#speed", "50")
    page.page.click("#play")
    page.page.wait_for_function(  # 24 s of run at 50x: half a second
        "document.getElementById('play').textContent === 'Play'", timeout=5000)
    assert page.clock() == pytest.approx(24.36, abs=0.01)  # played to the end


def test_scrubbing_moves_the_vehicle_and_the_plots_cursor(page: Page) -> None:
    start = page.vehicle()
    cursor = page.page.get_attribute(".plot .cursor", "x1")
    page.scrub(500)
    assert page.clock() == pytest.approx(12.18, abs=0.03)
    middle = page.vehicle()
    page.scrub(1000)
    assert len({start, middle, page.vehicle()}) == 3
    assert page.page.get_attribute(".plot .cursor", "x1") != cursor


def test_the_log_shows_the_lost_line_and_the_handler_jump(page: Page) -> None:
    page.scrub(100)
    assert page.page.locator("#log .lost").count() == 0
    page.scrub(1000)
    assert "line lost during MOV in mode 3" in (page.page.text_content("#log .lost") or "")
    assert ":96" in (page.page.text_content("#log .handler") or "")
    # The newest entry is in view: the log is scrolled to its bottom.
    assert page.page.eval_on_selector(
        "#log", "log => log.scrollTop + log.clientHeight >= log.scrollHeight - 1")
    assert (page.page.text_content("#line") or "").startswith(f"line {HANDLER_LINE}: ")


def test_the_camera_pane_shows_what_img_saw(page: Page) -> None:
    assert page.page.text_content("#frame") == "no IMG yet"
    page.page.goto(page.page.url + "#t=1")
    page.page.reload()
    assert page.page.text_content("#frame") == "IMG at 0.40 s: area 156, x 128, y 120"
    white = page.page.eval_on_selector("#camera", """camera => {
        const data = camera.getContext("2d").getImageData(0, 0, camera.width,
                                                           camera.height).data;
        let white = 0;
        for (let p = 0; p < data.length; p += 4)
            if (data[p] === 255 && data[p + 1] === 255 && data[p + 2] === 255) white++;
        return white; }""")
    assert 100 < white <= 156  # the line's pixels, less those the centroid's cross covers


def test_the_plots_are_drawn(page: Page) -> None:
    names = page.page.eval_on_selector_all(
        ".plot", "plots => plots.map(plot => plot.dataset.name)")
    assert names == ["ultrasonic", "odometry KYO", "image IMG", "wheel speeds, from the track"]
    for name in ("ultrasonic", "image IMG", "wheel speeds, from the track"):
        drawn = page.page.eval_on_selector(
            f'.plot[data-name="{name}"]', "plot => Array.from(plot.querySelectorAll("
            "'.series')).map(series => series.getBBox().width)")
        assert drawn and max(drawn) > 100, name
