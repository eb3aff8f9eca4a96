"""The browser tests' Debian chromium, driven by Playwright for Python
(tests/browser/install-chromium installs both; no browser of Playwright's own is ever
downloaded), and a page opened in it with what it logs and asks for watched."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterator
from types import ModuleType
from typing import Any

import pytest

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--no-first-run", "--disable-sync"]


def playwright_or_skip() -> ModuleType:
    """Playwright's synchronous API; called as a test module is imported, skips the
    module when chromium or Playwright is missing, saying how to install them."""
    if not os.access(CHROMIUM, os.X_OK):
        pytest.skip(f"{CHROMIUM} is missing: run tests/browser/install-chromium as root",
                    allow_module_level=True)
    sync_api: ModuleType = pytest.importorskip(
        "playwright.sync_api", reason="Playwright is missing: run tests/browser/install-chromium")
    return sync_api


@contextlib.contextmanager
def chromium(sync_api: ModuleType) -> Iterator[Any]:
    """Chromium, launched headless, until the block ends."""
    with sync_api.sync_playwright() as playwright:
        launched = playwright.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield launched
        launched.close()


class WatchedPage:
    """`address` open in a fresh context of `browser` (made with `context`'s options),
    with the errors and warnings it logged (`problems`) and every request it made that
    `own` does not call its own (`elsewhere`)."""

    def __init__(self, browser: Any, address: str, own: Callable[[str], bool],
                 **context: Any) -> None:
        self.context = browser.new_context(**context)
        self.page = self.context.new_page()
        self.problems: list[str] = []
        self.elsewhere: list[str] = []
        self._own = own
        self.page.on("console", self._console)
        self.page.on("pageerror", lambda error: self.problems.append(f"error: {error}"))
        self.page.on("request", self._request)
        self.page.goto(address)

    def _console(self, message: Any) -> None:
        if message.type in ("error", "warning"):
            self.problems.append(f"{message.type}: {message.text}")

    def _request(self, request: Any) -> None:
        if not self._own(request.url):
            self.elsewhere.append(request.url)
