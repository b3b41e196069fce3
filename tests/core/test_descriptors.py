"""Writes and reads on a non-blocking pseudo-terminal within a deadline: all of it, what is left, nothing.

Deadlines that should not be reached are generous (a loaded machine is slow; a call that succeeds returns at
once); timing is asserted only as bounds that a slow machine cannot break: a call waits at least until its
deadline before giving up, and gives up within a generous margin after it, not never."""

from __future__ import annotations

import os
import time
import tty

import pytest

from accelcal_rig.core.descriptors import read_within, write_within

#: A deadline not meant to be reached: the call returns as soon as it is done.
GENEROUS_S = 10.0


@pytest.fixture
def pty():
    master, slave = os.openpty()
    for fd in (master, slave):
        tty.setraw(fd)
        os.set_blocking(fd, False)
    yield master, slave
    for fd in (master, slave):
        os.close(fd)


def test_what_is_written_arrives_whole(pty) -> None:
    master, slave = pty
    assert write_within(master, b"REG? 0x00\n", time.monotonic() + GENEROUS_S) == 0
    assert read_within(slave, time.monotonic() + GENEROUS_S) == b"REG? 0x00\n"


def test_nothing_arrived_by_the_deadline_is_none(pty) -> None:
    """None only once the deadline has passed (it waited), and then at once (it did not wait on)."""
    _, slave = pty
    started = time.monotonic()
    assert read_within(slave, started + 0.05) is None
    assert time.monotonic() >= started + 0.05
    assert time.monotonic() - started < GENEROUS_S


def test_a_reader_that_stops_reading_leaves_the_rest_unwritten_at_the_deadline(pty) -> None:
    """Room is waited for until the deadline, no longer: part of the reply is left unwritten."""
    master, _ = pty
    reply = b"x" * 4_000_000  # far more than a pseudo-terminal buffers
    started = time.monotonic()
    left = write_within(master, reply, started + 0.2)
    assert 0 < left < len(reply)
    assert time.monotonic() >= started + 0.2
    assert time.monotonic() - started < GENEROUS_S
