"""Whatever a page sends the studio's `/studio`, each request is answered with its
result or with one of spec/studio.md's errors, never an internal error, and the
connection goes on (Hypothesis)."""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from served import TIMEOUT, Failed, Page, Served, page, sample_folder, serving

from rl1.lsp.studio.connection import Connection

ERRORS = {-32700, -32600, -32601, -32602, -32001, -32002, -32003, -32004, -32005, -32006,
          -32007}
JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-2**40, 2**40)
    | st.floats(allow_nan=False, allow_infinity=False)  # JSON has neither
    | st.text(max_size=20) | st.sampled_from(["sample.rob", "sample.world.toml", "../x.rob",
                                              "/etc/passwd", "IMG", "A<0", "a.rob",
                                              "\ud800.rob"]),
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


SURROGATE = "\ud800"  # what JSON's "\ud800" reads as: half of a pair, no character


@pytest.mark.parametrize("method, params, code", [
    ("files/read", {"path": f"{SURROGATE}.rob"}, -32001),
    ("files/save", {"path": f"{SURROGATE}.rob", "text": "(END)\n"}, -32001),
    ("run/launch", {"program": {"path": f"{SURROGATE}.rob"}}, -32001),
    ("world/check", {"text": f"# {SURROGATE}\n"}, -32602),
    ("world/check", {"text": "", "path": f"{SURROGATE}.world.toml"}, -32602),
    ("run/launch", {"program": {"text": "(END)\n"}, "world": {"text": SURROGATE}}, -32602),
    ("run/launch", {"program": {"text": "(END)\n"}, "sensors": {"text": SURROGATE}}, -32602),
    ("run/launch", {"program": {"text": "(END)\n", "name": SURROGATE}}, -32602),
])
def test_half_a_surrogate_pair_is_refused_as_no_text(client: Page, method: str,
                                                     params: dict[str, Any],
                                                     code: int) -> None:
    """Found by the hostile pass: each was an internal error (UnicodeEncodeError)."""
    with pytest.raises(Failed) as failed:
        client.request(method, params)
    assert failed.value.code == code, failed.value
    assert "\\ud800" in str(failed.value)


@pytest.mark.parametrize("constant", ["NaN", "Infinity", "-Infinity", "1e400"])
def test_nan_and_infinity_are_no_json(client: Page, constant: str) -> None:
    """Found by the hostile pass: Python's json reads them, and an id of NaN was
    answered with `"id": NaN`, which no page's JSON.parse reads."""
    client.send(f'{{"jsonrpc": "2.0", "id": {constant}, "method": "initialize"}}')
    answer = json.loads(client.connection.recv(timeout=TIMEOUT),
                        parse_constant=lambda name: pytest.fail(f"{name} in the answer"))
    assert answer["id"] is None and answer["error"]["code"] == -32700
    assert constant.lstrip("-") in answer["error"]["message"]


def test_a_name_too_long_for_the_debug_section_is_refused(client: Page) -> None:
    """Found by the hostile pass: an internal error (the .ilc's encoder refused it)."""
    with pytest.raises(Failed) as failed:
        client.request("run/launch", {"program": {"text": "(END)\n", "name": "x" * 256}})
    assert failed.value.code == -32602
    assert "255 bytes" in str(failed.value)


def test_a_program_deep_in_the_folder_runs(served: Served) -> None:
    """A path longer than the debug section holds is recorded as its file's name, as
    `rl1c build` records it (it was an internal error)."""
    deep = served.server.studio.folder.root / "/".join(["folder" * 10] * 5)
    deep.mkdir(parents=True)
    (deep / "deep.rob").write_text("(END)\n")
    with page(served) as client:
        path = (deep / "deep.rob").relative_to(served.server.studio.folder.root).as_posix()
        assert len(path) > 255
        assert client.request("run/launch", {"program": {"path": path}})["lines"] == [1]


LONG = "\u00e9" * 2**20  # 6 MiB of JSON escapes once quoted whole


@pytest.mark.parametrize("method, params, said", [
    (LONG, {}, "is no method of the studio"),
    ("files/read", {"path": LONG}, "is longer than"),
    ("files/save", {"path": LONG, "text": ""}, "is longer than"),
    ("files/save", {"path": "a.rob", "text": "", "encoding": LONG}, "`encoding` is"),
    ("run/launch", {"program": {"path": LONG}}, "is longer than"),
    ("run/launch", {"program": LONG}, "`program` is"),
    ("run/launch", {"program": {"path": "sample.rob"}, "level": [LONG]}, "`level` is"),
    ("run/launch", {"program": {"path": "sample.rob"}, "seed": LONG}, "`seed` is"),
    ("run/launch", {"program": {"path": "sample.rob"}, "stopOnEntry": LONG}, "`stopOnEntry`"),
    ("debug/setSpeed", {"speed": LONG}, "`speed` is"),
])
def test_an_error_quotes_an_excerpt_of_what_the_page_sent(client: Page, method: str,
                                                           params: dict[str, Any],
                                                           said: str) -> None:
    """Found by the hostile pass: each error quoted the page's value whole, and JSON's
    escapes made 54 MiB of it (9 Mi characters) an answer of 54 MiB, written at a peak
    of 262 to 370 MiB more for one page, past the bound of what pages hold."""
    with pytest.raises(Failed) as failed:
        client.request(method, params)
    assert said in str(failed.value)
    assert len(str(failed.value)) < 400, str(failed.value)[:200]


@pytest.mark.parametrize("line", [0, -5])
def test_a_breakpoint_on_no_line_is_refused(client: Page, line: int) -> None:
    """Found by the hostile pass: a line before the first (lines start at 1) was bound
    to the program's first line with code."""
    with pytest.raises(Failed) as failed:
        client.request("debug/setBreakpoints", {"lines": [{"line": line}]})
    assert failed.value.code == -32602
    assert "`line` (a whole number, 1 or more)" in str(failed.value)
