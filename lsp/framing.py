"""The base protocol's framing on a byte stream (standard input and output, a TCP
connection): `Content-Length` headers, each message's body, and what to do when a
client breaks them.

pygls' reader trusts its client: a huge `Content-Length` is read in one allocation
(MemoryError) or grows without bound as the data streams in, a header line longer than
64 KiB drops a TCP connection, and a header it does not recognise leaves it waiting for
a header that never comes. This reader bounds every read (a header line, a message),
accepts LF as well as CRLF line ends, and after broken framing skips to the next
`Content-Length` header; the transport says on standard error what it skipped.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from typing import BinaryIO

import click

MAX_MESSAGE = 64 * 2**20
"""The largest body accepted, in bytes: 6 times the largest document analysed, which
JSON's escapes may double or so."""
MAX_HEADER_LINE = 4096  # header lines are short: a longer one is not a header
CHUNK = 2**16  # bytes read at a time

_MARKER = b"content-length:"
_HEADER = re.compile(re.escape(_MARKER), re.IGNORECASE)
_LENGTH = re.compile(rb"content-length:[ \t]*(\d+)[ \t]*", re.IGNORECASE)
_FIELD = re.compile(rb"[!-9;-~]+:.*")  # any other header, such as Content-Type


def standard_streams() -> tuple[BinaryIO, BinaryIO]:
    """Standard input and output, the byte streams a client started the server on; a
    usage error (status 2) when either is closed (`<&-`, `>&-`), which Python leaves as
    None."""
    if sys.stdin is None or sys.stdout is None:
        closed = "input" if sys.stdin is None else "output"
        raise click.UsageError(f"standard {closed} is closed: a client starts this server "
                               "with its standard input and output as pipes")
    return sys.stdin.buffer, sys.stdout.buffer


Admission = Callable[[int], str | None]
"""Asked with a message's length at the end of its headers, before its body is read:
None to read it, else why it is skipped (transports.InFlight: what a server's sessions
hold between them)."""


class Framer:
    """Splits the bytes read into message bodies, without ever holding more than one
    message (up to `limit` bytes, and admitted by `admit`) and one chunk."""

    def __init__(self, limit: int = MAX_MESSAGE, admit: Admission | None = None) -> None:
        self.limit = limit
        self.admit = admit
        self.problems: list[str] = []  # what was skipped since last taken
        self._buffer = bytearray()
        self._length: int | None = None  # the Content-Length of the headers read so far
        self._body: int | None = None  # the headers are read: a body this long follows
        self._lost = False  # skipping up to the next Content-Length header

    @property
    def reading(self) -> int:
        """The length of the body being read (0 between messages)."""
        return self._body or 0

    def discard(self) -> None:
        """Let go of what is buffered: the stream has ended."""
        self._buffer = bytearray()
        self._body = self._length = None

    def feed(self, data: bytes) -> list[bytes]:
        """The bodies of the messages completed by `data`."""
        self._buffer += data
        bodies = []
        while (body := self._next()) is not None:
            bodies.append(body)
        return bodies

    def _next(self) -> bytes | None:
        buffer = self._buffer
        while True:
            if self._body is not None:
                if len(buffer) < self._body:
                    return None
                with memoryview(buffer) as view:
                    body = bytes(view[:self._body])
                    # A new buffer for the rest, lest the body's room be kept for good.
                    self._buffer = bytearray(view[self._body:])
                self._body = None
                return body
            if self._lost:
                found = _HEADER.search(buffer)
                if found is None:  # keep what may be the start of a header
                    del buffer[:max(0, len(buffer) - len(_MARKER) + 1)]
                    return None
                del buffer[:found.start()]
                self._lost = False
            end = buffer.find(b"\n", 0, MAX_HEADER_LINE)
            if end < 0:
                if len(buffer) < MAX_HEADER_LINE:
                    return None
                self._skip(f"a header line longer than {MAX_HEADER_LINE:,} bytes", 1)
                continue
            line = bytes(buffer[:end]).rstrip(b"\r").strip(b" \t")
            if not line:  # the end of the headers
                if self._length is None:
                    self._skip("a message without a valid Content-Length header", end + 1)
                    continue
                if self.admit is not None and (refused := self.admit(self._length)):
                    self._skip(f"a message of {self._length:,} bytes: {refused}", end + 1)
                    continue
                self._body, self._length = self._length, None
            elif (length := _LENGTH.fullmatch(line)) is not None:
                if int(length[1]) > self.limit:
                    self._skip(f"a message of {int(length[1]):,} bytes, over the limit of "
                               f"{self.limit:,}", end + 1)
                    continue
                self._length = int(length[1])
            elif _HEADER.match(line):
                self._skip(f"a Content-Length that is no number of bytes: {line[:60]!r}",
                           end + 1)
                continue
            elif not _FIELD.fullmatch(line):  # perhaps the rest of a body: skip a byte
                self._skip(f"a line that is no header: {line[:60]!r}", 1)
                continue
            del buffer[:end + 1]

    def _skip(self, problem: str, drop: int) -> None:
        del self._buffer[:drop]
        self._length = None
        self._lost = True
        self.problems.append(problem)


def frame(body: bytes) -> bytes:
    """A message as the server writes it: its length in bytes, then the body."""
    return b"Content-Length: %d\r\n\r\n%s" % (len(body), body)
