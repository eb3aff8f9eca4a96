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
