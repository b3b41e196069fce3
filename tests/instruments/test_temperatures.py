"""Temperatures of a whole fixture at one poll: the quick read after an agreed one, the bridges asked at
once, and every doubtful read settled the careful way."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.instruments.adxl355_driver import AGREED_FRESH_S, Adxl355
from accelcal_rig.instruments.adxl355_transport import SerialBridge
from accelcal_rig.instruments.line_port import LinePort
from accelcal_rig.instruments.temperatures import read_temperatures_together
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.sim.adxl355_bridge_server import SimulatedBridgeServer
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG
from tests.instruments.expected_protocol import ExpectedPort, expected_protocol

AGREE = [(b"R 06 2\n", b"=075D\n"), (b"R 06 2\n", b"=075D\n")]


def driver(line: LinePort, clock: VirtualClock) -> Adxl355:
    return Adxl355(SerialBridge(line, "memory"), "X-1", clock, ADXL355)


def test_after_an_agreed_reading_one_read_that_agrees_with_it_is_enough() -> None:
    clock = VirtualClock()
    with expected_protocol([*AGREE, (b"R 06 2\n", b"=075C\n")]) as line:
        sensor = driver(line, clock)
        assert sensor.read_temperature_c() == pytest.approx(25.0)
        clock.sleep(30.0)
        assert sensor.read_temperature_c() == pytest.approx(25.0 + 1 / 9.05)


def test_an_agreed_reading_too_old_is_not_trusted() -> None:
    clock = VirtualClock()
    with expected_protocol([*AGREE, *AGREE]) as line:
        sensor = driver(line, clock)
        sensor.read_temperature_c()
        clock.sleep(AGREED_FRESH_S + 1.0)
        assert sensor.read_temperature_c() == pytest.approx(25.0)


def test_a_torn_quick_read_falls_back_to_reads_that_agree() -> None:
    clock = VirtualClock()
    torn = (b"R 06 2\n", b"=085D\n")  # the high nibble a step ahead: ~28 °C off
    with expected_protocol([*AGREE, torn, (b"R 06 2\n", b"=075D\n"), (b"R 06 2\n", b"=075D\n")]) as line:
        sensor = driver(line, clock)
        sensor.read_temperature_c()
        assert sensor.read_temperature_c() == pytest.approx(25.0)


class LoggedPort(ExpectedPort):
    """An ExpectedPort that writes what happens on it into a log shared with other ports."""

    def __init__(self, name: str, conversation, log: list[str]) -> None:
        super().__init__(conversation)
        self._name, self._log = name, log

    def write(self, data: bytes) -> int:
        self._log.append(f"{self._name} sent")
        return super().write(data)

    def read(self, size: int = 1) -> bytes:
        if self._reply:
            self._log.append(f"{self._name} read")
        return super().read(size)


def test_the_fixture_is_asked_at_once_and_a_doubtful_sensor_alone_again() -> None:
    clock, log = VirtualClock(), []
    ports = [LoggedPort("A", [*AGREE, (b"R 06 2\n", b"=075D\n")], log),
             LoggedPort("B", [*AGREE, (b"R 06 2\n", b"=085D\n"), (b"R 06 2\n", b"=075D\n")], log)]  # B's tore
    sensors = [driver(LinePort(port, f"bridge {port._name}"), clock) for port in ports]  # type: ignore[arg-type]
    for sensor in sensors:
        sensor.read_temperature_c()
    log.clear()
    clock.sleep(10.0)
    assert read_temperatures_together(sensors) == pytest.approx([25.0, 25.0])
    assert log[:2] == ["A sent", "B sent"]  # both requests out before either reply is read
    assert log[2:4] == ["A read", "B read"]
    assert log[4:] == ["B sent", "B read"]  # then B alone, its own way
    for port in ports:
        port.assert_finished()


def test_a_fixture_of_tearing_parts_read_together_never_reports_a_torn_temperature() -> None:
    clock = VirtualClock()
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 3)
    servers = [SimulatedBridgeServer(lab, k, 2, temperature_tear_rate=0.05).start() for k in range(4)]
    sensors = [Adxl355(SerialBridge.open(s.path), d.serial, clock) for s, d in zip(servers, lab.duts)]
    try:
        true_c = np.array([lab.dut_true_c(k) for k in range(4)])
        readings = []
        for _ in range(150):
            readings.append(read_temperatures_together(sensors))
            clock.sleep(10.0)
        assert np.all(np.abs(np.array(readings) - true_c) < 0.5)
    finally:
        for sensor, server in zip(sensors, servers):
            sensor.close()
            server.stop()
