"""Whatever a page sends the studio's `/studio`, each request is answered with its
result or with one of spec/studio.md's errors, never an internal error, and the
connection goes on (Hypothesis)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from served import Failed, Page, Served, page, sample_folder, serving

from rl1.lsp.studio.connection import Connection

ERRORS = {-32700, -32600, -32601, -32602, -32001, -32002, -32003, -32004, -32005, -32006,
          -32007}
JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-2**40, 2**40) | st.floats(allow_nan=False)
    | st.text(max_size=20) | st.sampled_from(["sample.rob", "sample.world.toml", "../x.rob",
                                              "/etc/passwd", "IMG", "A<0", "a.rob"]),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(
        st.sampled_from(["path", "text", "name", "program", "world", "sensors", "level",
                         "seed", "speed", "stopOnEntry", "lines", "calls", "lostLines",
                         "line", "condition", "expression", "encoding", "version"]), inner,
        max_size=5),
    max_leaves=12)
METHODS = st.sampled_from(sorted(Connection.METHODS)) | st.text(max_size=12)


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Served]:
    folder = tmp_path_factory.mktemp("hostile") / "robots"
    folder.mkdir()
    with serving(sample_folder(folder)) as server:
        yield server


@pytest.fixture(scope="module")
def client(served: Served) -> Iterator[Page]:
    with page(served) as connection:
        yield connection


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(method=METHODS, params=st.dictionaries(st.sampled_from(
    ["path", "text", "program", "world", "sensors", "level", "speed", "lines", "calls",
     "expression", "stopOnEntry", "encoding", "version"]), JSON, max_size=4))
def test_any_request_is_answered(client: Page, method: str, params: dict[str, Any]) -> None:
    try:
        client.request(method, params)
    except Failed as failed:
        assert failed.code in ERRORS, failed
        assert str(failed)
    client.notifications.clear()
    assert client.request("initialize")["folder"]
    with pytest.raises(Failed):
        client.request("debug/evaluate", {})


def test_nothing_was_written_outside_the_folder(served: Served) -> None:
    # After the property (which sends "../x.rob" and "/etc/passwd" among the paths).
    outside = served.server.studio.folder.root.parent
    assert [path.name for path in outside.iterdir()] == ["robots"]
