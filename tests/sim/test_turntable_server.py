"""The simulated turntable controller, byte for byte on its pseudo-terminal as any client sees it: a move or
rate that is no number (`nan`, `inf`, `1e400`, `1_0`) or names no axis as a controller writes one is
refused `ERR …`, as every request it cannot carry out, and nothing moves; a line too long to be a request
is refused the same way, held only up to the bound, and the next request is answered."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.protocols.turntable_line import ACCELCAL_LINE, ACUTROL3000, TurntableProtocol
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.line_answers import MAX_LINE_BYTES
from accelcal_rig.sim.turntable_server import SimulatedTurntableServer
from tests.conftest import SIM_RIG
from tests.sim.line_client import LineClient, pty_client


@contextmanager
def served(protocol: TurntableProtocol) -> Iterator[tuple[SimulatedTurntableServer, VirtualLab, LineClient]]:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedTurntableServer(lab, protocol).start()
    try:
        with pty_client(server.endpoint) as client:
            yield server, lab, client
    finally:
        server.stop()


@pytest.mark.parametrize(("request_", "reply"), [
    (b"MOV 1 nan\n", b"ERR not a number: 'nan'\n"),
    (b"MOV 2 -inf\n", b"ERR not a number: '-inf'\n"),
    (b"MOV 3 1e400\n", b"ERR not a finite number: '1e400'\n"),
    (b"MOV 1 1_0.00000\n", b"ERR not a number: '1_0.00000'\n"),
    (b"MOV +1 10.00000\n", b"ERR no axis +1\n"),
    (b"MOV 1_0 10.00000\n", b"ERR no axis 1_0\n"),
    (b"RATE 1 nan 10.00000\n", b"ERR not a number: 'nan'\n"),
    (b"RATE 1 10.00000 inf\n", b"ERR not a number: 'inf'\n"),
])
def test_a_move_or_rate_that_is_no_number_is_refused_and_nothing_moves(request_: bytes, reply: bytes) -> None:
    with served(ACCELCAL_LINE) as (server, lab, client):
        client.send(request_)
        assert client.reply(b"\n") == reply
        client.send(b"BUSY?\n")
        assert client.reply(b"\n") == b"0\n"
        lab.clock.sleep(60.0)  # time for any motion the request began
        client.send(b"POS? 1\n")
        assert client.reply(b"\n") == b"0.000000\n"
        assert server.last_command is None  # a refused command is not the table's last
        np.testing.assert_array_equal(lab.motion.position_deg(lab.clock.now()), [0.0, 0.0, 0.0])
        np.testing.assert_array_equal([lab.motion.read_rate_deg_s(lab.clock.now(), axis) for axis in range(3)], 0.0)


def test_a_joined_move_with_one_axis_no_number_moves_no_axis() -> None:
    with served(ACUTROL3000) as (server, lab, client):
        for axis in (1, 2, 3):
            client.send(b":interlock:close %d\n:mode:position %d\n" % (axis, axis))  # unanswered
        client.send(b":demand:position 1,10.00000;:demand:position 2,nan;:demand:position 3,0.00000\n")
        assert client.reply(b"\n") == b"ERR not a number: 'nan'\n"
        lab.clock.sleep(60.0)  # time for any motion the request began
        client.send(b":read:position? 1\n")
        assert client.reply(b"\n") == b"0.00000\n"
        assert server.last_command is None
        client.send(b":demand:position 1,10.00000;:demand:position 2,0.00000;:demand:position 3,0.00000\n")
        client.send(b":read:position? 1\n")
        assert client.reply(b"\n") == b"0.00000\n"  # the move (unanswered) has been taken by now
        lab.clock.sleep(60.0)
        client.send(b":read:position? 1\n")
        angle_deg = float(client.reply(b"\n"))  # within the simulated table's accuracy
        assert angle_deg == pytest.approx(10.0, abs=0.01)  # set up all along: only the bad number was refused


def test_a_multi_megabyte_line_is_refused_held_only_to_the_bound_and_the_next_request_answered() -> None:
    with served(ACCELCAL_LINE) as (server, _, client):
        for _ in range(64):  # 4 MiB without a terminator
            client.send(b"M" * 65536)
        client.send(b"\nPOS? 2\n")
        assert client.reply(b"\n") == b"ERR unknown command '" + b"M" * 64 + b"'... (a line over 4096 bytes)\n"
        assert client.reply(b"\n") == b"0.000000\n"
        assert 0 < server.peak_buffered_bytes <= MAX_LINE_BYTES and server.buffered_bytes == 0
