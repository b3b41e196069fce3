"""A simulated device's line reader: requests cut at their terminator however the bytes arrive, and a line
longer than MAX_LINE_BYTES never held whole: answered as the device answers what it does not know (or not
at all), the next request served."""

from __future__ import annotations

import pytest

from accelcal_rig.sim.line_answers import ANY_LINE_END, MAX_LINE_BYTES, OVERLONG_HEAD_BYTES, LineAnswers


def answers(terminator: bytes = b"\r\n", overlong: bool = True) -> tuple[LineAnswers, list[bytes], list[str]]:
    """A reader that echoes each request upper-cased; (reader, replies written, heads of over-long lines)."""
    written: list[bytes] = []
    heads: list[str] = []

    def too_long(head: str) -> str:
        heads.append(head)
        return "ERR too long"

    reader = LineAnswers(lambda request: request.upper(), terminator, overlong=too_long if overlong else None)
    return reader, written, heads


def feed(reader: LineAnswers, written: list[bytes], data: bytes, chunk: int) -> None:
    for start in range(0, len(data), chunk):
        reader.feed(data[start:start + chunk], written.append)


@pytest.mark.parametrize("chunk", [1, 2, 3, 4095, 4096, 4097, 65536])
def test_a_line_of_exactly_the_bound_is_served_one_byte_more_is_not(chunk: int) -> None:
    reader, written, heads = answers()
    longest, one_more = b"a" * MAX_LINE_BYTES, b"b" * (MAX_LINE_BYTES + 1)
    feed(reader, written, longest + b"\r\n" + one_more + b"\r\nok\r\n", chunk)
    assert written == [b"A" * MAX_LINE_BYTES + b"\r\n", b"ERR too long\r\n", b"OK\r\n"]
    assert heads == ["b" * OVERLONG_HEAD_BYTES]
    assert reader.buffered_bytes == 0 and reader.peak_buffered_bytes <= MAX_LINE_BYTES + 1  # and a CR


@pytest.mark.parametrize("chunk", [1, 7, 4096, 65536])
def test_megabytes_without_a_terminator_are_held_to_the_bound_and_a_split_terminator_still_ends_them(chunk: int) -> None:
    reader, written, heads = answers()
    feed(reader, written, b"R 00 4" + b"x" * (2 << 20), chunk)
    assert written == [] and reader.buffered_bytes <= OVERLONG_HEAD_BYTES + 1
    reader.feed(b"\r", written.append)  # the terminator's first byte ends one read, its second begins the next
    reader.feed(b"\n?\r\n", written.append)
    assert written == [b"ERR too long\r\n", b"?\r\n"]
    assert heads == ["R 00 4" + "x" * (OVERLONG_HEAD_BYTES - 6)]
    assert reader.peak_buffered_bytes <= MAX_LINE_BYTES + 1


def test_a_device_silent_on_what_it_does_not_know_is_silent_on_an_over_long_line() -> None:
    reader, written, _ = answers(b"\n", overlong=False)
    feed(reader, written, b"z" * (3 * MAX_LINE_BYTES) + b"\nping\n", 1000)
    assert written == [b"PING\n"]


def test_requests_split_anywhere_and_several_in_one_read_are_each_answered_once() -> None:
    reader, written, _ = answers()
    feed(reader, written, b"one\r\ntwo\r\n\r\nthree\r\n", 1)
    reader.feed(b"four\r\nfive\r\nsi", written.append)
    reader.feed(b"x\r\n", written.append)
    assert written == [b"ONE\r\n", b"TWO\r\n", b"\r\n", b"THREE\r\n", b"FOUR\r\n", b"FIVE\r\n", b"SIX\r\n"]


@pytest.mark.parametrize("chunk", [1, 2, 3, 65536])
def test_a_device_reading_any_line_end_answers_cr_lf_and_cr_lf_each_once_whatever_the_reads(chunk: int) -> None:
    """A client's odd terminator is answered alone: an LF-ended request never joins the next one, and the LF of
    a CR LF split between two reads ends nothing more."""
    written: list[bytes] = []
    reader = LineAnswers(lambda request: request.upper(), ANY_LINE_END, b"\r\n")
    feed(reader, written, b"one\ntwo\rthree\r\nfour\n\nsix\r", chunk)
    reader.feed(b"\nseven\r\n", written.append)
    assert written == [b"ONE\r\n", b"TWO\r\n", b"THREE\r\n", b"FOUR\r\n", b"\r\n", b"SIX\r\n", b"SEVEN\r\n"]
    assert reader.buffered_bytes == 0
