"""Writes and reads on a non-blocking pseudo-terminal within a deadline: all of it, what is left, nothing."""

from __future__ import annotations

import os
import time
import tty

import pytest

from accelcal_rig.core.descriptors import read_within, write_within


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
    assert write_within(master, b"REG? 0x00\n", time.monotonic() + 1.0) == 0
    assert read_within(slave, time.monotonic() + 1.0) == b"REG? 0x00\n"


def test_nothing_arrived_by_the_deadline_is_none(pty) -> None:
    _, slave = pty
    started = time.monotonic()
    assert read_within(slave, started + 0.05) is None
    assert time.monotonic() - started < 1.0


def test_a_reader_that_stops_reading_leaves_the_rest_unwritten_at_the_deadline(pty) -> None:
    master, _ = pty
    reply = b"x" * 4_000_000  # far more than a pseudo-terminal buffers
    started = time.monotonic()
    left = write_within(master, reply, started + 0.2)
    assert 0 < left < len(reply)
    assert time.monotonic() - started < 2.0
