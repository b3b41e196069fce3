"""The simulated Modbus chamber controller, byte for byte over loopback TCP as any Modbus master sees it
(frames written here from the Modbus application protocol, not by pymodbus): a set point written as a NaN or
an infinite float is refused with exception 3, illegal data value (as half a float is), and the set point
before it stays; under injected faults, it carries out what it receives as a real one does."""

from __future__ import annotations

import socket
import struct
from collections.abc import Iterator

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.config.rig import FaultInjection
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import TransientInstrumentError
from accelcal_rig.instruments.chamber_modbus import ModbusChamber
from accelcal_rig.protocols.chamber_registers import register_map
from accelcal_rig.sim.chamber_server import SimulatedChamberServer
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG

F4T_SETPOINT = 2782


def float_words_low_first(pattern: int) -> tuple[int, int]:
    """A float32's bit pattern as the F4T's two registers, low word first."""
    return pattern & 0xFFFF, pattern >> 16


def write_registers(transaction: int, address: int, words: tuple[int, ...]) -> bytes:
    """Function 16 (write multiple registers) to unit 1, in its MBAP header."""
    pdu = struct.pack(">BHHB", 0x10, address, len(words), 2 * len(words)) + struct.pack(f">{len(words)}H", *words)
    return struct.pack(">HHHB", transaction, 0, len(pdu) + 1, 1) + pdu


def read_registers(transaction: int, address: int, count: int) -> bytes:
    pdu = struct.pack(">BHH", 0x03, address, count)
    return struct.pack(">HHHB", transaction, 0, len(pdu) + 1, 1) + pdu


def exchange(connection: socket.socket, request: bytes) -> bytes:
    """The whole reply frame to `request` (the MBAP length says how much follows the header)."""
    connection.sendall(request)
    reply = b""
    while len(reply) < 6 or len(reply) < 6 + struct.unpack(">H", reply[4:6])[0]:
        got = connection.recv(260)
        assert got, f"connection closed after {reply!r}"
        reply += got
    return reply


@pytest.fixture
def f4t() -> Iterator[tuple[SimulatedChamberServer, socket.socket]]:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedChamberServer(lab, register_map("watlow-f4t")).start()
    try:
        with socket.create_connection((server.host, server.port), timeout=10.0) as connection:
            yield server, connection
    finally:
        server.stop()


@pytest.mark.parametrize("pattern", [0x7FC00000, 0xFFC00000, 0x7F800001, 0x7F800000, 0xFF800000],
                         ids=["nan", "-nan", "signalling-nan", "inf", "-inf"])
def test_a_set_point_that_is_no_number_is_exception_3_and_the_old_one_stays(f4t, pattern: int) -> None:
    server, connection = f4t
    minus_40 = float_words_low_first(0xC2200000)
    assert exchange(connection, write_registers(1, F4T_SETPOINT, minus_40)) == bytes.fromhex(
        "0001 0000 0006 01 10 0ADE 0002")
    assert exchange(connection, write_registers(2, F4T_SETPOINT, float_words_low_first(pattern))) == bytes.fromhex(
        "0002 0000 0003 01 90 03")  # exception 3: illegal data value
    assert exchange(connection, read_registers(3, F4T_SETPOINT, 2)) == bytes.fromhex(
        "0003 0000 0007 01 03 04 0000 C220")  # -40.0, low word first
    assert server.last_setpoint_c == -40.0


class DropFirst:
    """Reply faults that lose the first reply and no other."""

    faults = FaultInjection()

    def __init__(self) -> None:
        self.drawn = 0

    def draw(self, allowed: tuple[str, ...]) -> str | None:
        self.drawn += 1
        return "drop" if self.drawn == 1 else None


def test_a_write_whose_reply_is_lost_is_carried_out_at_once_not_after_the_writes_that_follow() -> None:
    """A controller sets what it receives and its reply is what gets lost. Carried out only when the lost
    reply would have gone (seconds of wall time later: hours of a dry run's clock), the write of an earlier
    set point landed after the next one and took the chamber back (a dry run's ramp then timed out)."""
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedChamberServer(lab, register_map("watlow-f4t", {}), faults=DropFirst()).start()
    chamber = ModbusChamber.tcp(server.host, server.port, register_map("watlow-f4t", {}), timeout_s=0.2)
    try:
        with pytest.raises(TransientInstrumentError, match="no reply"):
            chamber.write_setpoint_c(-30.0)
        assert lab.thermal.setpoint_c == pytest.approx(-30.0)  # taken as it arrived
        chamber.reconnect()
        chamber.write_setpoint_c(-20.0)
        assert lab.thermal.setpoint_c == pytest.approx(-20.0) and server.last_setpoint_c == pytest.approx(-20.0)
    finally:
        chamber.close()
        server.stop()
