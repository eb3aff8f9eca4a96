"""Who may use the studio's server (spec/studio.md, "Routes"): the token on every route
and both WebSockets, the page's own Origin and Host only, the loopback address only; the
page and its files served, confined to the static folder, and a page saying how to build
it when it is not built."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from urllib.parse import quote, unquote

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from served import Served, get, page, sample_folder, serving
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect
from websockets.typing import Origin

from rl1.lsp.studio.server import BUILD_HELP, TOKEN_PLACEHOLDER

PAGE = f"""<!doctype html><script src="/static/studio.js?token={TOKEN_PLACEHOLDER}"></script>"""
ROUTES = ["/", "/static/studio.js", "/static/nothing.js", "/elsewhere"]
SOCKETS = ["/lsp", "/studio"]


@pytest.fixture(scope="module")
def static(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("static")
    (folder / "index.html").write_text(PAGE)
    (folder / "studio.js").write_text("console.log('studio')\n")
    (folder / "studio.css").write_text("body{}\n")
    return folder


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory, static: Path) -> Iterator[Served]:
    folder = sample_folder(tmp_path_factory.mktemp("folder"))
    (folder / "secret.txt").write_text("not for the page\n")
    os.symlink(folder / "secret.txt", static / "escape.js")
    with serving(folder, str(folder / "sample.rob"), static=static) as server:
        yield server


@pytest.mark.parametrize("route", ROUTES)
@pytest.mark.parametrize("token", [None, "", "wrong"])
def test_every_route_wants_the_token(served: Served, route: str, token: str | None) -> None:
    target = route if token is None else f"{route}?token={token}"
    answer = get(served, target)
    assert answer.status == 403
    assert b"token" in answer.body


def test_two_tokens_are_no_token(served: Served) -> None:
    assert get(served, f"/?token={served.token}&token={served.token}").status == 403


@pytest.mark.parametrize("route", SOCKETS)
@pytest.mark.parametrize("token", ["", "wrong"])
def test_both_websockets_want_the_token(served: Served, route: str, token: str) -> None:
    with pytest.raises(InvalidStatus) as refused:
        connect(served.url(route, token=token, scheme="ws"), open_timeout=30)
    assert refused.value.response.status_code == 403


@pytest.mark.parametrize("route", SOCKETS)
@pytest.mark.parametrize("origin", ["http://evil.example", "http://127.0.0.1:1",
                                    "https://127.0.0.1", "null"])
def test_a_websocket_from_another_origin_is_refused(served: Served, route: str,
                                                     origin: str) -> None:
    with pytest.raises(InvalidStatus) as refused:
        connect(served.url(route, scheme="ws"), origin=Origin(origin), open_timeout=30)
    assert refused.value.response.status_code == 403
    assert origin.encode() in refused.value.response.body


def test_the_pages_own_origin_and_programs_without_one_are_let_in(served: Served) -> None:
    for origin in (f"http://127.0.0.1:{served.port}", f"http://localhost:{served.port}", None):
        with page(served, origin) as client:
            assert client.request("initialize")["program"] == "sample.rob"


def test_an_http_request_from_another_origin_is_refused(served: Served) -> None:
    answer = get(served, f"/?token={served.token}", {"Origin": "http://evil.example"})
    assert answer.status == 403


@pytest.mark.parametrize("host", ["evil.example", "evil.example:{port}", "127.0.0.1:1",
                                  "127.0.0.2:{port}"])
def test_another_host_is_refused(served: Served, host: str) -> None:
    # DNS rebinding: a page of evil.example whose name resolves to 127.0.0.1.
    answer = get(served, f"/?token={served.token}", {"Host": host.format(port=served.port)})
    assert answer.status == 403
    assert b"host" in answer.body


@pytest.mark.parametrize("name", ["Host", "Origin"])
def test_a_header_given_twice_is_refused(served: Served, name: str) -> None:
    # Two Hosts or two Origins, one of them right, are a 403, not the server's error.
    own = f"127.0.0.1:{served.port}" if name == "Host" else f"http://127.0.0.1:{served.port}"
    answer = get(served, f"/?token={served.token}", [("Host", f"127.0.0.1:{served.port}"),
                                                     *([] if name == "Host" else [(name, own)]),
                                                     (name, own if name == "Host" else
                                                      "http://evil.example")])
    assert answer.status == 403, answer
    assert name.lower().encode() in answer.body.lower()


def test_it_listens_on_the_loopback_address_only(served: Served) -> None:
    assert served.server.addresses == [("127.0.0.1", served.port)]


def test_the_page_is_served_with_the_token_in_it(served: Served) -> None:
    answer = get(served, f"/?token={served.token}")
    assert answer.status == 200
    assert answer.body.decode() == PAGE.replace(TOKEN_PLACEHOLDER, served.token)
    assert answer.headers["Content-Type"] == "text/html; charset=utf-8"
    assert answer.headers["Referrer-Policy"] == "no-referrer"
    assert answer.headers["Cache-Control"] == "no-store"
    policy = answer.headers["Content-Security-Policy"]
    assert "script-src 'self';" in policy
    assert f"connect-src ws://127.0.0.1:{served.port} ws://localhost:{served.port};" in policy


def test_the_pages_files_are_served_with_their_types(served: Served) -> None:
    script = get(served, f"/static/studio.js?token={served.token}")
    assert (script.status, script.body) == (200, b"console.log('studio')\n")
    assert script.headers["Content-Type"] == "text/javascript; charset=utf-8"
    assert get(served, f"/static/studio.css?token={served.token}").headers[
        "Content-Type"] == "text/css; charset=utf-8"


@pytest.mark.parametrize("target", ["/static/../files.py", "/static/%2e%2e/server.py",
                                    "/static//etc/passwd", "/static/%2Fetc%2Fpasswd",
                                    "/static/escape.js", "/static/", "/static/nothing.js"])
def test_nothing_outside_the_pages_folder_is_served(served: Served, target: str) -> None:
    answer = get(served, f"{target}?token={served.token}")
    assert answer.status == 404
    assert b"not for the page" not in answer.body
    assert b"import" not in answer.body


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.one_of(st.text(max_size=300), st.lists(st.sampled_from(
    ["studio.js", "escape.js", "..", ".", "/", "%2e", "%2f", "%00", "\x00", "index.html",
     "~", "etc", "passwd"]), max_size=8).map("".join)))
def test_any_path_is_answered_and_never_escapes(served: Served, path: str) -> None:
    target = "/static/" + quote(path, safe="/.%")
    answer = get(served, f"{target}?token={served.token}")
    assert answer.status in (200, 404)
    assert b"not for the page" not in answer.body
    assert b"Traceback" not in answer.body
    if answer.status == 200:
        assert answer.body == (served.server.static / unquote(path).lstrip("/")).read_bytes()


def test_only_get_is_served(served: Served) -> None:
    assert get(served, f"/?token={served.token}", method="DELETE").status == 405


def test_an_unbuilt_page_is_a_503_saying_how_to_build_it(tmp_path: Path) -> None:
    with serving(sample_folder(tmp_path), static=tmp_path / "not-built") as served:
        answer = get(served, f"/?token={served.token}")
    assert answer.status == 503
    assert answer.headers["Content-Type"] == "text/html; charset=utf-8"
    assert BUILD_HELP.encode() in answer.body
    assert b"Traceback" not in answer.body
