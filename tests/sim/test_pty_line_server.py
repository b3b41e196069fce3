"""A simulated serial device on a pseudo-terminal: a line far longer than any request (megabytes without a
terminator) is held only up to the bound and answered as the device says, and the next request is served."""

from __future__ import annotations

from accelcal_rig.sim.line_answers import MAX_LINE_BYTES
from accelcal_rig.sim.pty_line_server import PtyLineServer
from tests.sim.line_client import pty_client


def test_a_multi_megabyte_line_is_held_to_the_bound_answered_and_the_next_request_served() -> None:
    server = PtyLineServer(lambda request: request.upper(), b"\r", overlong=lambda head: f"?{head[:3]}",
                           reply_terminator=b"\r\n").start()
    try:
        with pty_client(server.path) as client:
            for _ in range(128):  # 8 MiB, no terminator
                client.send(b"abc" + b"x" * 65533)
            client.send(b"\rping\r")
            assert client.reply(b"\r\n") == b"?abc\r\n"
            assert client.reply(b"\r\n") == b"PING\r\n"
        assert 0 < server.peak_buffered_bytes <= MAX_LINE_BYTES and server.buffered_bytes == 0
    finally:
        server.stop()


def test_a_device_that_answers_nothing_it_does_not_know_drops_an_over_long_line() -> None:
    server = PtyLineServer(lambda request: request.upper()).start()  # no `overlong`: silence
    try:
        with pty_client(server.path) as client:
            client.send(b"y" * (3 * MAX_LINE_BYTES) + b"\nping\n")
            assert client.reply(b"\n") == b"PING\n"
    finally:
        server.stop()
