"""The base protocol's framing, on bytes alone: messages come out whole however the
input is cut, and no input makes the reader fail or hold more than one message."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from rl1.lsp.framing import MAX_HEADER_LINE, Framer

bodies = st.lists(st.binary(max_size=300), max_size=8)


def framed(body: bytes, line_end: bytes = b"\r\n") -> bytes:
    return b"Content-Length: %d%s%s%s" % (len(body), line_end, line_end, body)


def feed_in_pieces(framer: Framer, data: bytes, cuts: list[int]) -> list[bytes]:
    out = []
    start = 0
    for cut in [*sorted(cuts), len(data)]:
        out += framer.feed(data[start:cut])
        start = cut
    return out


@given(bodies, st.lists(st.integers(0, 3000)), st.sampled_from([b"\r\n", b"\n"]))
def test_messages_come_out_whole_however_the_input_is_cut(
        messages: list[bytes], cuts: list[int], line_end: bytes) -> None:
    data = b"".join(framed(body, line_end) for body in messages)
    framer = Framer()
    assert feed_in_pieces(framer, data, cuts) == messages
    assert framer.problems == []


no_header = st.binary(max_size=5000).filter(lambda data: b"content-length" not in data.lower())


@given(no_header, bodies)
def test_after_garbage_and_a_blank_line_the_next_messages_are_read(
        garbage: bytes, messages: list[bytes]) -> None:
    framer = Framer(limit=10_000)
    framer.feed(garbage + b"\r\n\r\n")
    framer.problems.clear()
    assert framer.feed(b"".join(framed(body) for body in messages)) == messages


@given(st.lists(st.binary(max_size=2000), max_size=20))
def test_no_input_makes_the_reader_fail_or_hoard(chunks: list[bytes]) -> None:
    framer = Framer(limit=1000)
    for chunk in chunks:
        for body in framer.feed(chunk):
            assert len(body) <= 1000
        assert len(framer._buffer) <= 1000 + MAX_HEADER_LINE + len(chunk)


def test_a_message_over_the_limit_is_skipped_and_said() -> None:
    framer = Framer(limit=10)
    assert framer.feed(framed(b"x" * 11) + framed(b"ok")) == [b"ok"]
    assert framer.problems == ["a message of 11 bytes, over the limit of 10"]


plain_bodies = st.lists(st.binary(max_size=300).filter(
    lambda body: b"content-length" not in body.lower()), max_size=8)


@given(plain_bodies, st.integers(2, 300), st.lists(st.integers(0, 3000)))
def test_a_message_not_admitted_is_skipped_whole_and_the_next_read(
        messages: list[bytes], admitted: int, cuts: list[int]) -> None:
    """The transports' shared bound on bytes in flight: asked with each message's length
    before its body is read; a message refused is skipped, and said."""
    asked: list[int] = []

    def admit(length: int) -> str | None:
        asked.append(length)
        return None if length <= admitted else "too much in flight"

    data = b"".join(framed(body) + framed(b"ok") for body in messages)
    framer = Framer(admit=admit)
    assert feed_in_pieces(framer, data, cuts) == [
        read for body in messages
        for read in ([body] if len(body) <= admitted else []) + [b"ok"]]
    assert asked == [length for body in messages for length in (len(body), 2)]
    assert framer.problems == [f"a message of {len(body):,} bytes: too much in flight"
                               for body in messages if len(body) > admitted]


def test_reading_is_the_length_of_the_body_being_read_until_it_is_whole() -> None:
    framer = Framer()
    assert framer.feed(b"Content-Length: 5\r\n\r\nab") == []
    assert framer.reading == 5
    assert framer.feed(b"cde") == [b"abcde"]
    assert framer.reading == 0
    framer.feed(b"Content-Length: 5\r\n\r\nab")
    framer.discard()
    assert framer.reading == 0
    assert framer.feed(b"Content-Length: 2\r\n\r\nok") == [b"ok"]
