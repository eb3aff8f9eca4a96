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
from dataclasses import dataclass, field

from hypothesis import given
from hypothesis import strategies as st

from rl1.lsp import transports
from rl1.lsp.framing import MAX_MESSAGE
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
    """A session reading its messages of `sizes` bytes one after another, `piece` bytes
    at a time; each message read is handled, and its bytes let go of."""

    sizes: list[int]
    piece: int
    held: int = 0  # of the message being read
    read: list[int] = field(default_factory=list)  # the indexes of the messages read
    refused: list[int] = field(default_factory=list)  # and of those refused
    closed: bool = False  # refused, and reading no more

    @property
    def reading(self) -> int | None:
        """The index of the message being read, None once all are read or refused."""
        done = len(self.read) + len(self.refused)
        return None if self.closed or done == len(self.sizes) else done

    def holding(self) -> int:
        return self.held


def _beyond_free(sender: Sender) -> int:
    return max(0, sender.held - FREE_IN_FLIGHT)


@dataclass
class Sent:
    peak: int = 0  # the greatest sum of the bytes held beyond the free shares
    # The messages that passed their free share while no other session held beyond its own.
    alone: list[tuple[Sender, int]] = field(default_factory=list)


def _send(senders: Sequence[Sender], turns: Sequence[int], release_refused: bool) -> Sent:
    """Each turn, the sender of that index (modulo their number) asks for the next piece
    of its message, and holds it if admitted; a refused sender holds what it had read,
    and reads no more (a WebSocket connection closed, its frames held until it is lost),
    or, with `release_refused`, lets go of it and reads its next message (a TCP message
    skipped). Once `turns` is spent, the senders take turns round-robin until each has
    read or been refused all it sends."""
    in_flight = InFlight()
    sent = Sent()
    with contextlib.ExitStack() as stack:
        for sender in senders:
            stack.enter_context(in_flight.counting(sender, sender.holding))
        for turn in itertools.chain(turns, itertools.count()):
            if all(sender.reading is None for sender in senders):
                break
            sender = senders[turn % len(senders)]
            if (message := sender.reading) is None:
                continue
            size = sender.sizes[message]
            more = min(sender.piece, size - sender.held)
            if sender.held <= FREE_IN_FLIGHT < sender.held + more and not any(
                    _beyond_free(other) for other in senders if other is not sender):
                sent.alone.append((sender, message))
            if in_flight.refusal(sender, more) is None:
                sender.held += more
                if sender.held == size:
                    sender.read.append(message)
                    sender.held = 0
            else:
                sender.refused.append(message)
                if release_refused:
                    sender.held = 0
                else:
                    sender.closed = True
            sent.peak = max(sent.peak, sum(map(_beyond_free, senders)))
    return sent


def test_of_eight_large_messages_read_at_once_the_first_is_read_whole() -> None:
    """Eight WebSocket clients sent 60 MiB each at once, their frames interleaved: all
    grew together until the bound was full, and each was refused midway, none read (on
    a loaded machine, every time). The first to need more than its free share keeps
    room for its message, and the others share what is left."""
    senders = [Sender(sizes=[60 * MiB], piece=MiB // 4) for _ in range(MAX_SESSIONS)]
    round_robin = list(range(MAX_SESSIONS)) * (60 * 4)
    sent = _send(senders, round_robin, release_refused=False)
    assert sent.alone == [(senders[0], 0)]
    assert senders[0].read == [0]
    assert sent.peak <= MAX_IN_FLIGHT
    assert all(sender.refused == [0] for sender in senders[2:])


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
    """Up to MAX_SESSIONS sessions, each sending up to three messages, all received in
    pieces of one size (a transport reads what has come, up to the same size each
    time), or each whole (TCP's admission)."""
    piece = draw(st.sampled_from([2**16, MiB, 8 * MiB, MAX_MESSAGE]))
    size = st.integers(0, MAX_MESSAGE) | st.integers(MAX_MESSAGE // 2, MAX_MESSAGE)
    return [Sender(sizes=sizes, piece=piece) for sizes in draw(st.lists(
        st.lists(size, min_size=1, max_size=3), min_size=1, max_size=MAX_SESSIONS))]


@given(senders=senders(), turns=st.lists(st.integers(0, MAX_SESSIONS - 1), max_size=200),
       release_refused=st.booleans())
def test_whatever_the_interleaving_the_bound_holds_and_large_messages_are_read(
        senders: list[Sender], turns: list[int], release_refused: bool) -> None:
    """For every interleaving of messages of up to MAX_MESSAGE bytes: the bytes held
    beyond the free shares never pass MAX_IN_FLIGHT, a message within its free share is
    always read, and so is a message that passes its free share while no other session
    holds beyond its own (such as the first to need more than that): the others'
    messages, begun before or after, do not make it refused midway."""
    sent = _send(senders, turns, release_refused)
    assert sent.peak <= MAX_IN_FLIGHT
    for sender in senders:
        small = [index for index, size in enumerate(sender.sizes) if size <= FREE_IN_FLIGHT]
        assert not set(small) & set(sender.refused)
    for sender, message in sent.alone:
        assert message in sender.read, (sender.sizes, sender.refused)
    if any(size > FREE_IN_FLIGHT for sender in senders for size in sender.sizes):
        assert sent.alone, "some message passes its free share while alone"


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
    """The WebSocket outbox (rl1-lsp's sessions' and the studio pages') counted an
    answer, then asked whether its session might hold it: refused, the answer was not
    sent but stayed counted against the others until the session ended. A studio page
    could also leave 128 MiB unread whatever the others held, past the bound."""
    async def answer() -> None:
        stream = _Stream()
        with _bound_full() as in_flight:
            writer = transports.WebSocketOutbox(
                stream, functools.partial(in_flight.refusal, stream))
            with in_flight.counting(stream, lambda: writer.unsent):
                writer.write(ANSWER)
            writer.close()
        assert stream.transport.aborted and writer.unsent == 0

        page = _Stream()
        with _bound_full() as in_flight:
            outbox = transports.WebSocketOutbox(page, functools.partial(
                in_flight.refusal, page), "a page")
            with in_flight.counting(page, lambda: outbox.unsent):
                outbox.send(ANSWER.decode())
            outbox.close()
            outbox.send("{}")  # closed, as when its page has gone: nothing is asked
        assert page.transport.aborted and outbox.unsent == 0

    asyncio.run(answer())
