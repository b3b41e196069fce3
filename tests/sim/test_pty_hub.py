"""One thread answers every simulated serial device: a client that stops reading holds the others up for at
most a reply's write deadline, and never the server's stop.

The test waits on events (the stuck reply has begun to arrive, the other device's answer has come), each
with a generous deadline. Timing is asserted as bounds a slow machine cannot break: the other device is
held up at least until the stuck write's deadline (so the hold-up really happened, on the one thread), and
it and the stop come within a generous margin after it (so the hold-up ends: a write that blocked for ever
would never let either through)."""

from __future__ import annotations

import os
import select
import time

from accelcal_rig.core.descriptors import read_within
from accelcal_rig.sim.pty_line_server import WRITE_DEADLINE_S, PtyLineServer

#: Beyond the write deadline, for scheduling on a loaded machine; far short of "for ever".
MARGIN_S = 3.0


def ask(path: str, request: bytes, deadline_s: float) -> bytes:
    """The reply line to `request` (what came of it, if the deadline passes first)."""
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    try:
        os.write(fd, request)
        reply, end = b"", time.monotonic() + deadline_s
        while not reply.endswith(b"\n"):
            got = read_within(fd, end)
            if not got:
                break
            reply += got
        return reply
    finally:
        os.close(fd)


def test_a_client_that_stops_reading_a_long_reply_holds_up_other_devices_briefly_and_stop_not_at_all() -> None:
    flood = PtyLineServer(lambda request: "x" * 500_000, name="flood").start()
    echo = PtyLineServer(lambda request: request.upper(), name="echo").start()
    reader = os.open(flood.path, os.O_RDWR | os.O_NOCTTY)
    try:
        sent = time.monotonic()
        os.write(reader, b"all of it\n")  # and never read: the reply fills the pty and waits
        # The reply has begun: the hub's thread is in its write, waiting for room that never comes.
        assert select.select([reader], [], [], WRITE_DEADLINE_S + MARGIN_S)[0], "the long reply never began"
        assert ask(echo.path, b"ping\n", WRITE_DEADLINE_S + MARGIN_S) == b"PING\n"  # another device answers…
        answered = time.monotonic()
        assert answered - sent >= WRITE_DEADLINE_S  # … only once the stuck write gave up (one thread) …
        assert answered - sent < WRITE_DEADLINE_S + MARGIN_S  # … and then promptly
        flood.stop()  # the stuck one stops (a blocking write would hold its lock for ever)
        assert time.monotonic() - sent < WRITE_DEADLINE_S + MARGIN_S
    finally:
        os.close(reader)
        echo.stop()
