"""The studio's server (spec/studio.md): one asyncio server of the `websockets` package
on the loopback address, answering plain HTTP GETs for the page and its files and two
WebSockets, `/lsp` (the language server, lsp/transports.py) and `/studio`
(connection.py).

Every request passes the same gate before anything else: its Host is this server's
(against DNS rebinding), it presents the token in its query, and its Origin, if any,
is the page's own. A page of another site cannot then reach the server (it has no
token, and the browser sends its Origin), nor can another local user who cannot read
the command's output.
"""

from __future__ import annotations

import functools
import logging
import mimetypes
import secrets
from collections.abc import Callable
from dataclasses import dataclass, field
from http import HTTPStatus
from pathlib import Path
from urllib.parse import parse_qs, unquote, urlsplit

from websockets.asyncio.server import ServerConnection, serve
from websockets.datastructures import Headers
from websockets.exceptions import ConnectionClosed
from websockets.frames import CloseCode
from websockets.http11 import Request, Response

from .. import transports
from .connection import Connection, Studio
from .files import Folder, Refused, Unusable
from .language import new_session

log = logging.getLogger(__name__)

HOST = "127.0.0.1"
STATIC = Path(__file__).with_name("static")
TOKEN_PLACEHOLDER = "__RL1_STUDIO_TOKEN__"
BUILD_HELP = "make studio-page"  # in the checkout: the page's packages, then esbuild
_TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8",
          ".css": "text/css; charset=utf-8", ".json": "application/json",
          ".map": "application/json", ".svg": "image/svg+xml", ".png": "image/png",
          ".woff2": "font/woff2"}


def new_token() -> str:
    return secrets.token_urlsafe(32)


@dataclass(slots=True)
class Gate:
    """Who may use the server: the token, and this server's own addresses."""

    token: str
    port: int = 0  # known once the server listens

    def refusal(self, request: Request) -> str | None:
        """Why `request` is refused, or None."""
        hosts = {f"{HOST}:{self.port}", f"localhost:{self.port}"}
        if len(request.headers.get_all("Origin")) > 1:
            return "a request with two Origin headers: send one"
        if request.headers.get_all("Host") not in ([host] for host in hosts):
            return ("the request names another host than this server: open the address "
                    "rl1c studio printed")
        tokens = parse_qs(urlsplit(request.path).query).get("token", [])
        if len(tokens) != 1 or not secrets.compare_digest(tokens[0].encode(),
                                                          self.token.encode()):
            return ("a wrong or missing token: open the address rl1c studio printed, with "
                    "its ?token=")
        origin = request.headers.get("Origin")
        if origin is not None and origin not in {f"http://{host}" for host in hosts}:
            return (f"a page of {origin} may not use the studio: only the page rl1c studio "
                    "serves may")
        return None

    def policy(self) -> str:
        sockets = " ".join(f"ws://{host}:{self.port}" for host in (HOST, "localhost"))
        return ("default-src 'none'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
                f"img-src 'self' data:; font-src 'self'; connect-src {sockets}; "
                "base-uri 'none'; form-action 'none'; frame-ancestors 'none'")


@dataclass(slots=True)
class Server:
    """The studio's state: the gate, the shared setting, and who is connected."""

    gate: Gate
    studio: Studio
    static: Path = STATIC
    lsp: transports.WebSocketSessions = field(default_factory=transports.WebSocketSessions)
    pages: int = 0
    addresses: list[tuple[str, int]] = field(default_factory=list)  # listened on

    # HTTP

    def process_request(self, connection: ServerConnection, request: Request
                        ) -> Response | None:
        refused = self.gate.refusal(request)
        if refused is not None:
            return self._text(HTTPStatus.FORBIDDEN, f"rl1c studio: {refused}")
        path = urlsplit(request.path).path
        if path in ("/lsp", "/studio"):
            return None  # the WebSocket handshake goes on
        if request.method != "GET":
            return self._text(HTTPStatus.METHOD_NOT_ALLOWED,
                              f"rl1c studio: {request.method} is not served: only GET")
        if path == "/":
            return self._index()
        if path.startswith("/static/"):
            return self._static(unquote(path.removeprefix("/static/")))
        return self._text(HTTPStatus.NOT_FOUND, f"rl1c studio: no page at {path}")

    def _index(self) -> Response:
        try:
            page = Folder(self.static).read("index.html").decode()
        except (OSError, Refused, Unusable, UnicodeDecodeError):
            return self._response(HTTPStatus.SERVICE_UNAVAILABLE, _NOT_BUILT.encode(),
                                  _TYPES[".html"])
        return self._response(HTTPStatus.OK,
                              page.replace(TOKEN_PLACEHOLDER, self.gate.token).encode(),
                              _TYPES[".html"])

    def _static(self, path: str) -> Response:
        try:
            data = Folder(self.static).read(path)
        except (OSError, Refused, Unusable):
            return self._text(HTTPStatus.NOT_FOUND, f"rl1c studio: no file {path} in the page")
        suffix = Path(path).suffix
        kind = _TYPES.get(suffix) or mimetypes.types_map.get(suffix, "application/octet-stream")
        return self._response(HTTPStatus.OK, data, kind)

    def _text(self, status: HTTPStatus, text: str) -> Response:
        return self._response(status, f"{text}\n".encode(), "text/plain; charset=utf-8")

    def _response(self, status: HTTPStatus, body: bytes, kind: str) -> Response:
        headers = Headers([
            ("Content-Type", kind), ("Content-Length", str(len(body))),
            ("Cache-Control", "no-store"), ("X-Content-Type-Options", "nosniff"),
            ("Referrer-Policy", "no-referrer"),
            ("Content-Security-Policy", self.gate.policy()), ("Connection", "close")])
        return Response(status.value, status.phrase, headers, body)

    # WebSockets

    async def handle(self, connection: ServerConnection) -> None:
        path = urlsplit(connection.request.path).path if connection.request else ""
        if path == "/lsp":
            folder = self.studio.folder
            await self.lsp.serve(connection, lambda: new_session(folder))
        elif path == "/studio":
            await self._studio(connection)

    async def _studio(self, connection: ServerConnection) -> None:
        if self.pages >= transports.MAX_SESSIONS:
            log.warning("a page beyond the %d served at once: refused", transports.MAX_SESSIONS)
            transports.fail_websocket(
                connection, CloseCode.TRY_AGAIN_LATER,
                f"rl1c studio serves {transports.MAX_SESSIONS} pages at once: close one")
            return
        assert isinstance(connection, self.lsp.connection_class)
        self.pages += 1
        outbox = transports.WebSocketOutbox(
            connection, functools.partial(self.lsp.in_flight.refusal, connection), "a page")
        page = Connection(self.studio, outbox.send, lambda: outbox.unsent)
        heard = False  # a page that says nothing holds a place only so long
        try:
            # Its bytes in flight are bounded together with the language server's
            # sessions' (transports.InFlight), as each of them counts its own.
            with self.lsp.in_flight.counting(connection,
                                             lambda: connection.received + outbox.unsent):
                async with transports.opening_deadline(lambda: heard,
                                                       connection.transport.abort,
                                                       "a page sent no message"):
                    while True:
                        message = await transports.read_text(connection)
                        heard = True
                        await page.receive(message)
                        # The library keeps the last frame it read until the next.
                        connection.received, message = len(message), b""
        except ConnectionClosed as closed:
            log.info("a page's connection ended: %s", closed)
        finally:
            self.pages -= 1
            page.close()
            outbox.close()
            # What its run held (the program's instructions, the world, the simulator's
            # generators) is left in reference cycles, which only a collection frees:
            # some 0.15 MiB a page, kept for good (bench/studio_pages.py).
            self.lsp.collector.count()


async def serve_studio(server: Server, port: int, listening: Callable[[int], None]) -> None:
    """Serve until cancelled; `listening` is told the port once the server listens."""
    async with serve(server.handle, HOST, port, process_request=server.process_request,
                     server_header=None, **server.lsp.serving()) as listener:
        server.addresses = [socket.getsockname()[:2] for socket in listener.sockets]
        server.gate.port = server.addresses[0][1]
        listening(server.gate.port)
        await listener.serve_forever()


_NOT_BUILT = f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>RL/I studio: the page is not built</title>
</head><body><h1>The studio's page is not built</h1>
<p>rl1c studio serves the page from <code>{STATIC}</code>, which has no
<code>index.html</code>. Build it from its sources in editors/studio/ (Node.js needed),
in the checkout's folder, then reload:</p>
<pre>{BUILD_HELP}</pre>
<p>An installed rl1 package ships the page built; this is a checkout without it.</p>
</body></html>
"""
