"""One thread answers every simulated serial device: a client that stops reading holds the others up for at
most a reply's write deadline, and never the server's stop."""

from __future__ import annotations

import os
import time

from accelcal_rig.sim.pty_line_server import WRITE_DEADLINE_S, PtyLineServer


def ask(path: str, request: bytes, deadline_s: float = 5.0) -> bytes:
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    try:
        os.write(fd, request)
        reply, end = b"", time.monotonic() + deadline_s
        while not reply.endswith(b"\n") and time.monotonic() < end:
            reply += os.read(fd, 65536)
        return reply
    finally:
        os.close(fd)


def test_a_client_that_stops_reading_a_long_reply_holds_up_other_devices_briefly_and_stop_not_at_all() -> None:
    flood = PtyLineServer(lambda request: "x" * 500_000, name="flood").start()
    echo = PtyLineServer(lambda request: request.upper(), name="echo").start()
    reader = os.open(flood.path, os.O_RDWR | os.O_NOCTTY)
    try:
        os.write(reader, b"all of it\n")  # and never read: the reply fills the pty and waits
        time.sleep(0.2)
        started = time.monotonic()
        assert ask(echo.path, b"ping\n") == b"PING\n"  # another device answers once the write gives up…
        assert time.monotonic() - started < WRITE_DEADLINE_S + 1.0
        flood.stop()  # … and the stuck one stops (a blocking write would hold its lock for ever)
        assert time.monotonic() - started < WRITE_DEADLINE_S + 2.0
    finally:
        os.close(reader)
        echo.stop()
