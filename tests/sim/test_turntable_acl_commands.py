"""The ACL commands a simulated ACUTROL3000 carries out beyond its profile (sim/turntable_acl.py), byte for byte
over its pty as a plain client sends them: interlock open, reset and close (TM-8004-C §4.5.1, 4.5.5, 4.5.6),
the one-command mode form and ALL (§4.7, §2.4), rate mode on its own at Rate mode's limits (§4.7.5, 4.3.6,
4.6.2, 4.6.8), the relative position demand (§4.3.2), the acceleration read (§4.10.1), the utility settings
(§4.14.1, 4.14.2); on the length-prefixed link each answer in its block (§2), and the project's driver naming
an opened interlock as the profile's fault."""

from __future__ import annotations

import os
import struct
import time
from collections.abc import Iterator
from contextlib import contextmanager

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.core.descriptors import read_within
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.line_port import LinePort
from accelcal_rig.instruments.turntable_serial import SerialTurntable
from accelcal_rig.protocols import acl_blocks
from accelcal_rig.protocols.turntable_line import turntable_protocol
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.turntable_server import SimulatedTurntableServer
from tests.conftest import SIM_RIG
from tests.sim.line_client import DEADLINE_S, LineClient, pty_client

GPIB = turntable_protocol("acutrol3000", {"setup_pause_s": 0.0})
ACKED = turntable_protocol("acutrol3000", {"setup_pause_s": 0.0, "acknowledgement": "length-prefixed"})


class Controller:
    """A fresh simulated ACUTROL3000 (the sim rig: three axes at 20 °/s, no rate limits of its own) and a
    plain client of it."""

    def __init__(self, client: LineClient, server: SimulatedTurntableServer, lab: VirtualLab) -> None:
        self.client, self.server, self.lab = client, server, lab

    def ask(self, request: bytes) -> bytes:
        self.client.send(request)
        return self.client.reply(b"\n")

    def tell(self, request: bytes) -> None:
        """A setting: unanswered (the next reply read is the next query's, so nothing came back)."""
        self.client.send(request)

    def wait(self, seconds: float) -> None:
        """Simulated time passes once every request sent so far has been carried out."""
        assert self.ask(b"*STB?\n") in (b"0\n", b"65\n")
        self.lab.clock.sleep(seconds)


@contextmanager
def controller(protocol=GPIB) -> Iterator[Controller]:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedTurntableServer(lab, protocol).start()
    try:
        with pty_client(server.path) as client:
            yield Controller(client, server, lab)
    finally:
        server.stop()


def test_an_opened_interlock_reads_open_until_closed_and_a_trip_stays_until_reset() -> None:
    with controller() as acl:
        acl.tell(b":INT:OPEN 1\n")
        assert acl.ask(b":INTerlock? 1;:INTerlock? 2\n") == b"Open;0\n"
        assert acl.ask(b"*STB?\n") == b"65\n"
        acl.server.faults[1] = "Fault"  # axis 2 trips
        acl.tell(b":I:C 1;C 2\n")
        assert acl.ask(b":interlock? 1;:interlock? 2\n") == b"0;Fault\n"  # a trip is frozen
        acl.tell(b":I:R\n")
        assert acl.ask(b":interlock? 2\n") == b"Open\n"
        acl.tell(b":INT:RES;CLOS 2\n")
        assert acl.ask(b":interlock? 1;:interlock? 2\n") == b"0;0\n"
        assert acl.ask(b"*STB?\n") == b"0\n"


def test_an_opened_axis_comes_to_rest_and_does_not_move_until_set_up_again() -> None:
    with controller() as acl:
        acl.tell(b":I:C 1;:M:P 1\n")
        acl.tell(b":D:P 1,100\n")
        acl.wait(1.0)  # 20 of 100 degrees
        acl.tell(b":I:O 1\n")
        acl.wait(10.0)
        assert acl.ask(b":R:P? 1;:R:R? 1\n") == b"20.00000;0.00000\n"
        acl.tell(b":D:P 1,50\n")
        acl.wait(10.0)
        assert acl.ask(b":R:P? 1\n") == b"20.00000\n"
        acl.tell(b":mode:rate 1;:dem:rate 1,5\n")  # nor turn
        acl.wait(10.0)
        assert acl.ask(b":R:R? 1\n") == b"0.00000\n"


def test_the_one_command_mode_form_and_all_axes() -> None:
    with controller() as acl:
        acl.tell(b":Mode ALL,Pos\n")
        assert acl.ask(b":M? 1;:M? 2;:M? 3\n") == b"P;P;P\n"
        acl.tell(b":mode 2,rate\n")
        assert acl.ask(b":M? 2\n") == b"R\n"
        assert acl.ask(b":mode 1,a\n") == b"ERR unknown command ':mode 1,a'\n"  # Arate or Abort (§2.7)
        assert acl.ask(b":mode 1,synt\n") == b"ERR unknown command ':mode 1,synt'\n"  # not simulated
        assert acl.ask(b":Mode? ALL\n") == b"ERR no axis ALL\n"  # ALL is for commands only (§2.4)


def test_rate_mode_on_its_own_turns_at_the_rate_modes_limits() -> None:
    with controller() as acl:
        acl.tell(b":lim:rate r,1,12;:lim:acc rate,1,6\n")
        acl.tell(b":mode:rate 1\n")
        acl.tell(b":dem:rate 1,30\n")  # held to the rate limit
        acl.wait(1.0)
        assert acl.ask(b":read:rate? 1;acc? 1\n") == b"6.00000;6.00000\n"
        acl.wait(5.0)
        assert acl.ask(b":R:R 1;A 1\n") == b"12.00000;0.00000\n"
        acl.tell(b":D:R 1, -6\n")
        acl.wait(1.0)
        assert acl.ask(b":R:A 1;R 1\n") == b"-6.00000;6.00000\n"
        assert acl.ask(b":L:R? R,1;:LIM:ACC? R,1\n") == b"12.00000;6.00000\n"


def test_a_rate_demand_outside_rate_mode_waits_for_it() -> None:
    with controller() as acl:
        acl.tell(b":lim:acc r,1,1000\n")
        acl.tell(b":demand:rate 1, 05.730\n")
        acl.wait(5.0)
        assert acl.ask(b":read:rate 1\n") == b"0.00000\n"
        acl.tell(b":mode:rate 1\n")
        acl.wait(5.0)
        assert acl.ask(b":read:rate 1\n") == b"5.73000\n"


def test_a_relative_position_demand_steps_from_the_demand() -> None:
    with controller() as acl:
        acl.tell(b":I:C 1;:M:P 1\n")
        acl.tell(b":D:P 1,10\n")
        acl.tell(b":DEM:Delta 1,-45.0\n")
        acl.wait(10.0)
        assert round(float(acl.ask(b":R:P? 1\n")), 2) == -35.0
        assert acl.ask(b":DEM:DEL? 2;DEL? 1\n") == b"0.00000;-45.00000\n"


def test_limits_per_mode_and_axis() -> None:
    with controller() as acl:
        assert acl.ask(b":LIM:ACC? P,1;:L:R? P,1;:L:R? R,3\n") == b"100.00000;20.00000;20.00000\n"
        acl.tell(b":LIM:ACC P,1,1500.0\n")
        acl.tell(b":lim:rate synt,2,1000\n")
        assert acl.ask(b":limit:acc? pos,1;:limit:rate? s,2;:limit:rate? pos,2\n") == \
            b"1500.00000;1000.00000;20.00000\n"
        assert acl.ask(b":L:R? A,1;:L:R? Off,1\n") == b"0.00000;0.00000\n"  # forced to zero (§4.6.8)
        assert acl.ask(b":LIM:ACC P,1,0\n") == b"ERR unknown command ':LIM:ACC P,1,0'\n"
        assert acl.ask(b":L:R? X,1\n") == b"ERR unknown command ':L:R? X,1'\n"
        assert acl.ask(b":L:R? P,4\n") == b"ERR no axis 4\n"
        assert acl.ask(b":LIM:ACC? P,1\n") == b"1500.00000\n"  # a refused line changes nothing


def test_lockout_and_format() -> None:
    with controller() as acl:
        assert acl.ask(b":U:L?\n") == b"OFF\n"
        acl.tell(b":utility:lockout on\n")
        assert acl.ask(b":U:L?;:U:F?\n") == b"ON;FLOAT\n"
        assert acl.ask(b":u:f f ; :R:P 1 \n") == b"0.00000\n"
        assert acl.ask(b":U:F BIN\n") == b"ERR unknown command ':U:F BIN'\n"  # binary answers: not simulated


def _block(fd: int) -> tuple[int, bytes]:
    """One response block: (error code, text)."""
    data, end = b"", time.monotonic() + DEADLINE_S
    while len(data) < acl_blocks.PREFIX_BYTES or len(data) < acl_blocks.PREFIX_BYTES + struct.unpack(
            "<iI", data[:acl_blocks.PREFIX_BYTES])[1]:
        got = read_within(fd, end)
        assert got, f"no block within {DEADLINE_S} s (have {data!r})"
        data += got
    code, length = struct.unpack("<iI", data[:acl_blocks.PREFIX_BYTES])
    return code, data[acl_blocks.PREFIX_BYTES:]


def test_on_the_length_prefixed_link_every_command_gets_its_block() -> None:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedTurntableServer(lab, ACKED).start()
    fd = os.open(server.path, os.O_RDWR | os.O_NOCTTY)
    try:
        for request, expected in ((b":utility:lockout on\n", (0, b"OK")), (b":interlock:open 1\n", (0, b"OK")),
                                  (b":interlock:reset 1\n", (0, b"OK")), (b":interlock:close 1\n", (0, b"OK")),
                                  (b":mode:rate 1\n", (0, b"OK")), (b":demand:rate 1, 05.730\n", (0, b"OK")),
                                  (b":read:acc 1\n", (0, b"100.00000")),  # ramping
                                  (b":limit:rate? r,1\n", (0, b"20.00000")), (b":limit:acc? r,1\n", (0, b"100.00000")),
                                  (b":mode:synt 1\n", (acl_blocks.UNKNOWN_COMMAND,
                                                       b"ERR unknown command ':mode:synt 1'"))):
            os.write(fd, request)
            assert _block(fd) == expected, request
    finally:
        os.close(fd)
        server.stop()


def test_the_driver_names_an_opened_interlock_as_a_fault_of_its_axis() -> None:
    with controller() as acl:
        acl.tell(b":int:open 2\n")
        assert acl.ask(b":interlock? 2\n") == b"Open\n"
        line = LinePort.open(acl.server.path, "turntable", 9600, 1.0)
        try:
            with pytest.raises(InstrumentError, match=r"axis 2: controller fault Open"):
                SerialTurntable(line, "pty", GPIB, 3).in_position()
        finally:
            line.close()
