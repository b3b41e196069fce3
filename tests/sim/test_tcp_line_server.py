"""A simulated line device on loopback TCP: a line far longer than any request (megabytes without a
terminator) is held only up to the bound and answered as the device says, on each connection apart, and
the next request is served."""

from __future__ import annotations

from accelcal_rig.sim.line_answers import MAX_LINE_BYTES
from accelcal_rig.sim.tcp_line_server import TcpLineServer
from tests.sim.line_client import tcp_client


def test_a_multi_megabyte_line_is_held_to_the_bound_answered_and_the_next_request_served() -> None:
    server = TcpLineServer(lambda request: request.upper(), b"\r\n", overlong=lambda head: f"?{head[:3]}").start()
    try:
        with tcp_client(server.endpoint) as flooding, tcp_client(server.endpoint) as other:
            for _ in range(256):  # 16 MiB, no terminator
                flooding.send(b"abc" + b"x" * 65533)
            other.send(b"meanwhile\r\n")  # another connection is served all along
            assert other.reply(b"\r\n") == b"MEANWHILE\r\n"
            flooding.send(b"\r\nping\r\n")
            assert flooding.reply(b"\r\n") == b"?abc\r\n"
            assert flooding.reply(b"\r\n") == b"PING\r\n"
            assert 0 < server.peak_buffered_bytes <= MAX_LINE_BYTES + 1 and server.buffered_bytes == 0
    finally:
        server.stop()
