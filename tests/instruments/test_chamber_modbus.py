"""The Modbus chamber driver against the simulated controller, over real Modbus TCP on loopback."""

from __future__ import annotations

import socket
import struct

import pytest
from pyModbusTCP.client import ModbusClient as IndependentModbusClient

from accelcal_rig.config.load import load_rig
from accelcal_rig.config.rig import ChamberConfig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.chamber_modbus import ModbusChamber, denormal_float32
from accelcal_rig.instruments.limits import LimitedChamber
from accelcal_rig.protocols.chamber_registers import register_map
from accelcal_rig.sim.chamber_server import SimulatedChamberServer
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG


@pytest.fixture
def served():
    """Start a simulated controller for a map; yield (server, lab, clock); stop them all after."""
    servers = []

    def start(profile: str, **overrides):
        clock = VirtualClock()
        lab = VirtualLab(load_rig(SIM_RIG).model, clock, 0)
        server = SimulatedChamberServer(lab, register_map(profile, overrides)).start()
        servers.append(server)
        return server, lab, clock

    yield start
    for server in servers:
        server.stop()


@pytest.mark.parametrize(("profile", "overrides"), [("watlow-f4", {}), ("watlow-f4t", {}),
                                                    ("watlow-f4t", {"word_order": "big"})])
def test_driver_runs_the_chamber_through_each_map(served, profile: str, overrides: dict) -> None:
    server, lab, clock = served(profile, **overrides)
    chamber = ModbusChamber.tcp(server.host, server.port, register_map(profile, overrides))
    try:
        assert "PV 23.0 °C" in chamber.identify()
        chamber.write_setpoint_c(-40.5)
        assert chamber.read_setpoint_c() == pytest.approx(-40.5)
        assert lab.thermal.setpoint_c == pytest.approx(-40.5)
        clock.sleep(3600)
        assert chamber.read_temperature_c() == pytest.approx(-40.5, abs=0.3)
        assert not chamber.alarm_active()
        chamber.set_power(False)
        clock.sleep(1800)
        halfway = chamber.read_temperature_c()
        assert -40.5 + 10 < halfway < 23.0 - 10  # off: relaxing towards the room (45 min time constant)
        clock.sleep(6 * 3600)
        assert chamber.read_temperature_c() == pytest.approx(23.0, abs=0.3)  # and back at ambient
    finally:
        chamber.close()


def test_an_independent_modbus_peer_reads_the_documented_encodings(served) -> None:
    """pyModbusTCP (not pymodbus) reads our server: F4 −20.5 °C is 0xFF33; F4T 23.5 °C is [0x0000, 0x41BC]."""
    server, lab, _ = served("watlow-f4")
    lab.thermal.set_setpoint(0.0, -20.5)
    peer = IndependentModbusClient(host=server.host, port=server.port, unit_id=1, timeout=2.0)
    assert peer.read_holding_registers(300, 1) == [0xFF33]
    assert peer.read_holding_registers(0, 1) == [5270]         # model code
    assert peer.read_holding_registers(606, 1) == [1]          # decimals
    assert peer.write_single_register(300, 256)                # 25.6 °C written by the peer
    assert lab.thermal.setpoint_c == pytest.approx(25.6)
    peer.close()

    server, lab, _ = served("watlow-f4t")
    lab.thermal.set_setpoint(0.0, 23.5)
    peer = IndependentModbusClient(host=server.host, port=server.port, unit_id=1, timeout=2.0)
    assert peer.read_holding_registers(2782, 2) == [0x0000, 0x41BC]
    high, low = 0xC222, 0x0000                                 # −40.5 °C, low word first
    assert struct.unpack(">f", struct.pack(">HH", high, low))[0] == -40.5
    assert peer.write_multiple_registers(2782, [low, high])
    assert lab.thermal.setpoint_c == -40.5
    assert peer.read_holding_registers(2790, 1) is None        # not in the map: Modbus exception
    peer.close()


def test_wrong_register_map_is_a_one_line_error_naming_the_endpoint(served) -> None:
    server, _, _ = served("watlow-f4t")
    chamber = ModbusChamber.tcp(server.host, server.port, register_map("watlow-f4"))
    with pytest.raises(InstrumentError, match=rf"chamber \(modbus-tcp 127.0.0.1:{server.port}\): register 0 refused"):
        chamber.identify()
    chamber.close()


def test_wrong_word_order_is_caught_by_plausibility(served) -> None:
    server, _, _ = served("watlow-f4t", word_order="big")
    chamber = ModbusChamber.tcp(server.host, server.port, register_map("watlow-f4t"))
    with pytest.raises(InstrumentError, match="wrong register map or word order"):
        chamber.identify()
    chamber.close()


def test_decimals_that_disagree_with_the_map_are_refused(served) -> None:
    server, _, _ = served("watlow-f4")
    chamber = ModbusChamber.tcp(server.host, server.port, register_map("watlow-f4", {"decimals": 2}))
    with pytest.raises(InstrumentError, match="1 decimal places .* the map expects 2"):
        chamber.identify()
    chamber.close()


def test_refused_connection_names_the_endpoint() -> None:
    with socket.socket() as probe:  # a port with nothing listening
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    with pytest.raises(InstrumentError, match=rf"chamber \(modbus-tcp 127.0.0.1:{port}\): cannot connect"):
        ModbusChamber.tcp("127.0.0.1", port, register_map("watlow-f4"), timeout_s=0.5)


def test_out_of_limit_setpoint_never_reaches_the_wire(served) -> None:
    server, _, _ = served("watlow-f4")
    chamber = LimitedChamber(ModbusChamber.tcp(server.host, server.port, register_map("watlow-f4")),
                             ChamberConfig(min_setpoint_c=-40, max_setpoint_c=85, safe_setpoint_c=20))
    with pytest.raises(InstrumentError, match="-60 °C refused"):
        chamber.write_setpoint_c(-60)
    assert server.last_setpoint_c is None
    chamber.write_setpoint_c(-40)
    assert server.last_setpoint_c == -40
    chamber.close()


def test_the_simulated_f4_serves_its_limits_and_clamps_beyond_them(served) -> None:
    server, lab, _ = served("watlow-f4")
    raw = ModbusChamber.tcp(server.host, server.port, register_map("watlow-f4"))
    assert raw.controller_limits_c() == lab.controller_limits_c == (-70.0, 180.0)
    raw.write_setpoint_c(190.0)  # what a controller does with a set point beyond its limits: clamps it
    assert raw.read_setpoint_c() == 180.0
    raw.close()


def test_a_chamber_near_zero_is_not_taken_for_swapped_words() -> None:
    """Swapped words of a round temperature give a float32 denormal; a chamber at 0 °C reads small normal floats
    (a seeded dry run read 7.5e-7 °C once and was aborted as a wrong word order before this)."""
    high, low = struct.unpack(">HH", struct.pack(">f", 23.5))          # 0x41BC, 0x0000
    swapped = struct.unpack(">f", struct.pack(">HH", low, high))[0]   # its words the other way round
    assert denormal_float32(swapped)
    assert not any(denormal_float32(v) for v in (0.0, 7.54998e-07, -1e-30, 1.2e-38))
