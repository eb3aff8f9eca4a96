"""transports.InFlight, the bound of the bytes a server's sessions hold between them,
driven directly: sessions are counters, and each step one of them asks for the next
piece of its message, as the WebSocket transport asks for each chunk it receives (the
TCP transport asks once, for the whole body, which is one piece here)."""

from __future__ import annotations

import asyncio
import contextlib
import functools
import itertools
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from hypothesis import given
from hypothesis import strategies as st

from rl1.lsp import transports
from rl1.lsp.framing import MAX_MESSAGE
from rl1.lsp.studio import server
from rl1.lsp.transports import (
    FREE_IN_FLIGHT,
    MAX_IN_FLIGHT,
    MAX_SESSIONS,
    RESERVED_IN_FLIGHT,
    InFlight,
)

MiB = 2**20


@dataclass(eq=False)  # a session, known by its identity
class Sender:
    """A session reading one message of `size` bytes, `piece` bytes at a time."""

    size: int
    piece: int
    held: int = 0
    refused: str | None = None

    @property
    def read(self) -> bool:
        return self.held == self.size

    def holding(self) -> int:
        return self.held

    def wants(self) -> int:
        return min(self.piece, self.size - self.held)


def _beyond_free(senders: Sequence[Sender]) -> int:
    return sum(max(0, sender.held - FREE_IN_FLIGHT) for sender in senders)


@dataclass
class Sent:
    peak: int  # the greatest sum of the bytes held beyond the free shares
    first_large: Sender | None  # the first to ask for more than its free share


def _send(senders: Sequence[Sender], turns: Sequence[int], release_refused: bool) -> Sent:
    """Each turn, the sender of that index (modulo their number) asks for its next piece,
    and holds it if admitted; a refused sender asks no more, and holds what it had read
    (a WebSocket connection's frames until it is lost) or, with `release_refused`, lets
    go of it (a TCP message skipped). Once `turns` is spent, the senders take turns
    round-robin until each has read its message or been refused."""
    in_flight = InFlight()
    sent = Sent(peak=0, first_large=None)
    with contextlib.ExitStack() as stack:
        for sender in senders:
            stack.enter_context(in_flight.counting(sender, sender.holding))
        for turn in itertools.chain(turns, itertools.count()):
            waiting = [s for s in senders if not s.read and s.refused is None]
            if not waiting:
                break
            sender = senders[turn % len(senders)]
            if sender not in waiting:
                continue
            more = sender.wants()
            if sent.first_large is None and sender.held + more > FREE_IN_FLIGHT:
                sent.first_large = sender
            if (refused := in_flight.refusal(sender, more)) is None:
                sender.held += more
            else:
                sender.refused = refused
                if release_refused:
                    sender.held = 0
            sent.peak = max(sent.peak, _beyond_free(senders))
    return sent


def test_of_eight_large_messages_read_at_once_the_first_is_read_whole() -> None:
    """Eight WebSocket clients sent 60 MiB each at once, their frames interleaved: all
    grew together until the bound was full, and each was refused midway, none read (on
    a loaded machine, every time). The first to need more than its free share keeps
    room for its message, and the others share what is left."""
    senders = [Sender(size=60 * MiB, piece=MiB // 4) for _ in range(MAX_SESSIONS)]
    round_robin = list(range(MAX_SESSIONS)) * (60 * 4)
    sent = _send(senders, round_robin, release_refused=False)
    assert sent.first_large is senders[0]
    assert senders[0].read, senders[0].refused
    assert sent.peak <= MAX_IN_FLIGHT
    assert all(sender.refused is not None for sender in senders[2:])


def test_a_refusal_says_what_the_others_hold_and_what_to_do() -> None:
    in_flight = InFlight()
    with in_flight.counting("first", lambda: 40 * MiB), \
            in_flight.counting("second", lambda: 0):
        assert in_flight.refusal("first") is None  # it takes the reservation
        assert in_flight.refusal("second", 60 * MiB) is None
        assert in_flight.refusal("second", 66 * MiB) == (
            "the server holds 64 MiB for other clients' messages and answers, and 128 "
            "MiB at most between them; send it again when they are done")


def test_the_reservation_passes_on_when_its_message_is_done() -> None:
    """Once its holder holds no more than its free share (its message read), the next
    session to need more takes the reservation, and its message of MAX_MESSAGE bytes
    fits whatever the others were admitted meanwhile."""
    held = {"first": 0, "second": 0, "third": 0}
    in_flight = InFlight()
    with contextlib.ExitStack() as stack:
        for name in held:
            stack.enter_context(in_flight.counting(name, functools.partial(held.__getitem__, name)))
        assert in_flight.refusal("first", MAX_MESSAGE) is None
        held["first"] = MAX_MESSAGE
        shared = MAX_IN_FLIGHT - RESERVED_IN_FLIGHT + FREE_IN_FLIGHT
        assert in_flight.refusal("second", shared + 1) is not None
        assert in_flight.refusal("second", shared) is None
        held["second"] = shared
        assert in_flight.refusal("third", FREE_IN_FLIGHT + 1) is not None
        held["first"] = 0  # read and handled
        assert in_flight.refusal("third", MAX_MESSAGE) is None
        held["third"] = MAX_MESSAGE
        assert in_flight.refusal("second", 1) is not None
        assert in_flight.refusal("first", FREE_IN_FLIGHT + 1) is not None


def test_a_session_that_ends_gives_back_the_reservation() -> None:
    in_flight = InFlight()
    with in_flight.counting("second", lambda: 0):
        with in_flight.counting("first", lambda: 10 * MiB):
            assert in_flight.refusal("first") is None
            assert in_flight.refusal("second", MAX_IN_FLIGHT) is not None
        assert in_flight.refusal("second", MAX_MESSAGE) is None


@st.composite
def senders(draw: st.DrawFn) -> list[Sender]:
    """Up to MAX_SESSIONS messages, received in pieces of one size (a transport reads
    what has come, up to the same size each time), or each whole (TCP's admission)."""
    piece = draw(st.sampled_from([2**16, MiB, 8 * MiB, MAX_MESSAGE]))
    sizes = st.integers(0, MAX_MESSAGE) | st.integers(MAX_MESSAGE // 2, MAX_MESSAGE)
    return [Sender(size=size, piece=piece)
            for size in draw(st.lists(sizes, min_size=1, max_size=MAX_SESSIONS))]


@given(senders=senders(), turns=st.lists(st.integers(0, MAX_SESSIONS - 1), max_size=200),
       release_refused=st.booleans())
def test_whatever_the_interleaving_the_bound_holds_and_one_large_message_is_read(
        senders: list[Sender], turns: list[int], release_refused: bool) -> None:
    """For every interleaving of messages of up to MAX_MESSAGE bytes: the bytes held
    beyond the free shares never pass MAX_IN_FLIGHT, a message within its free share is
    always read, and so is the first message to need more than that."""
    sent = _send(senders, turns, release_refused)
    assert sent.peak <= MAX_IN_FLIGHT
    assert all(sender.read for sender in senders if sender.size <= FREE_IN_FLIGHT)
    assert sent.first_large is None or sent.first_large.read, sent.first_large.refused


class _Transport:
    def __init__(self) -> None:
        self.aborted = False
        self.buffered = 0

    def abort(self) -> None:
        self.aborted = True

    def get_write_buffer_size(self) -> int:
        return self.buffered


class _Stream:
    """What _TcpWriter writes to (an asyncio.StreamWriter), and what the WebSocket
    writers send on (a websockets ServerConnection)."""

    def __init__(self) -> None:
        self.transport = _Transport()
        self.written: list[bytes | str] = []

    def is_closing(self) -> bool:
        return self.transport.aborted

    def write(self, data: bytes) -> None:
        self.written.append(data)
        self.transport.buffered += len(data)

    async def send(self, text: str) -> None:
        self.written.append(text)


@contextlib.contextmanager
def _bound_full() -> Iterator[InFlight]:
    """An InFlight whose bound another session holds whole (the reservation too)."""
    in_flight = InFlight()
    with in_flight.counting("other", lambda: FREE_IN_FLIGHT + MAX_IN_FLIGHT):
        assert in_flight.refusal("other") is None
        yield in_flight


ANSWER = b" " * (2 * MiB)  # beyond a session's free share


def test_a_tcp_answer_past_the_bound_is_not_written() -> None:
    """The TCP writer wrote an answer, then asked whether its session might hold it."""
    stream = _Stream()
    with _bound_full() as in_flight:
        writer = transports._TcpWriter(stream, functools.partial(  # type: ignore[arg-type]
            in_flight.refusal, stream))
        with in_flight.counting(stream, lambda: writer.unread):
            writer.write(ANSWER)
    assert stream.transport.aborted
    assert stream.written == []


def test_a_websocket_answer_past_the_bound_is_not_counted() -> None:
    """The WebSocket writers (rl1-lsp's and the studio page's) counted an answer, then
    asked whether their session might hold it: refused, the answer was not sent but
    stayed counted against the others until the session ended. A studio page could
    also leave 128 MiB unread whatever the others held, past the bound."""
    async def answer() -> None:
        stream = _Stream()
        with _bound_full() as in_flight:
            writer = transports._WebSocketWriter(
                stream, functools.partial(in_flight.refusal, stream))
            with in_flight.counting(stream, lambda: writer.unsent):
                writer.write(ANSWER)
            writer.close()
        assert stream.transport.aborted and writer.unsent == 0

        page = _Stream()
        with _bound_full() as in_flight:
            outbox = server._Outbox(page, functools.partial(  # type: ignore[arg-type]
                in_flight.refusal, page))
            with in_flight.counting(page, lambda: outbox.unsent):
                outbox.send(ANSWER.decode())
            outbox.close()
            outbox.send("{}")  # closed, as when its page has gone: nothing is asked
        assert page.transport.aborted and outbox.unsent == 0

    asyncio.run(answer())
