"""The fixtures of the tests that drive a studio of Listing 1: `folder` (a
`sample_folder`), `served` (the studio serving it, Listing 1 open) shared by a module's
tests, and `client` (a page of it) for each test. A test module imports them, under
these names of their own, to have the fixtures (pytest finds them by their `name`)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from served import Page, Served, page, sample_folder, serving


@pytest.fixture(scope="module", name="folder")
def listing_1_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return sample_folder(tmp_path_factory.mktemp("robots"))


@pytest.fixture(scope="module", name="served")
def listing_1_served(folder: Path) -> Iterator[Served]:
    with serving(folder, "sample.rob") as server:
        yield server


@pytest.fixture(name="client")
def listing_1_page(served: Served) -> Iterator[Page]:
    with page(served) as connection:
        yield connection
