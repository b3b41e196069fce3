"""The simulated ADXL355 at register level: FIFO filling, overflow and status bits, and the bridge's capture."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.instruments import adxl355
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.sim.adxl355_bridge_server import CAPTURE_CAPACITY_SAMPLES, SimulatedAdxl355, capture_rules
from accelcal_rig.sim.bridge_capture import CaptureRequests
from accelcal_rig.sim.bridge_refusals import Refusal
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG

ODR_HZ = 125.0


@pytest.fixture
def part():
    clock = VirtualClock()
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 5)
    device = SimulatedAdxl355(lab, 0)
    device.write(adxl355.REG_FILTER, ADXL355.odr_code(ODR_HZ))
    device.write(adxl355.REG_POWER_CTL, 0x00)  # measure
    return device, clock


def status_and_entries(device: SimulatedAdxl355) -> tuple[int, int]:
    status, entries = device.read(adxl355.REG_STATUS, 2)
    return status, entries


def test_the_fifo_fills_at_the_data_rate(part) -> None:
    device, clock = part
    clock.sleep(10 / ODR_HZ)
    status, entries = status_and_entries(device)
    assert entries == 30 and status & adxl355.STATUS_DATA_RDY and not status & adxl355.STATUS_FIFO_OVR
    codes, carried = adxl355.decode_fifo(device.read(adxl355.REG_FIFO_DATA, 288))
    assert codes.shape == (10, 3) and carried == b""
    assert status_and_entries(device)[1] == 0


def test_an_undrained_fifo_overflows_keeps_the_newest_and_status_read_clears_the_flag(part) -> None:
    device, clock = part
    clock.sleep(100 / ODR_HZ)
    device.read(adxl355.REG_TEMP2, 2)  # a temperature read changes nothing about the FIFO
    status, entries = status_and_entries(device)
    assert entries == 96 and status & adxl355.STATUS_FIFO_OVR and status & 0x02
    assert not status_and_entries(device)[0] & adxl355.STATUS_FIFO_OVR  # cleared by the read above
    codes, _ = adxl355.decode_fifo(device.read(adxl355.REG_FIFO_DATA, 288))
    assert codes.shape == (32, 3)
    newest = device.lab.duts[0].truth_log[-1]
    assert newest[0] == pytest.approx(68 / ODR_HZ) and newest[2] == 32  # samples 68…99, not 0…31


def test_a_capture_delivers_consecutive_samples_in_pieces(part) -> None:
    device, clock = part
    clock.sleep(50 / ODR_HZ)  # stale samples: the capture starts after them
    start_raw = device.start_capture(200)
    clock.sleep(120 / ODR_HZ)
    first, not_yet = device.fetch_capture(0)
    clock.sleep(200 / ODR_HZ)  # more than the rest: the capture stops at 200
    second, end_raw = device.fetch_capture(120)
    assert device.fetch_capture(0)[0] == first + second  # asked again: the same samples
    assert (len(first) // 9, len(second) // 9) == (120, 80)
    assert not_yet is None and end_raw is not None  # the end temperature comes with the completing piece
    true_c = device.lab.dut_true_c(0)
    for raw in (start_raw, end_raw):
        assert float(ADXL355.temperature.celsius(raw)) == pytest.approx(true_c, abs=0.3)
    codes, _ = adxl355.decode_fifo(first + second)
    assert codes.shape == (200, 3) and np.abs(codes).max() < ADXL355.channel("accel").code_max
    log = [entry for entry in device.lab.duts[0].truth_log if entry[0] >= 50 / ODR_HZ]
    assert [entry[2] for entry in log] == [120, 80]
    assert log[1][0] == pytest.approx(log[0][1])  # the second piece starts where the first ended


def test_a_capture_larger_than_the_buffer_is_refused_by_the_bridge(part) -> None:
    device, _ = part
    capture = CaptureRequests(device, CAPTURE_CAPACITY_SAMPLES, capture_rules())
    with pytest.raises(Refusal, match=rf"^bad count \(decimal 1\.\.{CAPTURE_CAPACITY_SAMPLES}\)$"):
        capture.start(str(CAPTURE_CAPACITY_SAMPLES + 1))
    assert capture.start(str(CAPTURE_CAPACITY_SAMPLES)).startswith("=")


def test_standby_refuses_a_capture_and_clears_the_fifo(part) -> None:
    device, clock = part
    clock.sleep(10 / ODR_HZ)
    device.write(adxl355.REG_POWER_CTL, adxl355.POWER_CTL_STANDBY)
    assert status_and_entries(device)[1] == 0
    with pytest.raises(Refusal, match="^capture needs the part measuring$"):
        CaptureRequests(device, CAPTURE_CAPACITY_SAMPLES, capture_rules()).start("10")


def test_writes_the_part_ignores_change_nothing(part) -> None:
    """As the part (and the reference firmware's C model of it): a read-only register, and RANGE or FILTER while
    measuring, keep what they hold (the bridge refuses such writes before they reach the part)."""
    device, _ = part
    before = device.read(0x00, 4), device.read(adxl355.REG_FILTER, 1), device.read(adxl355.REG_RANGE, 1)
    device.write(0x00, 0x12)
    device.write(adxl355.REG_FILTER, 0x00)
    device.write(adxl355.REG_RANGE, 0x83)
    assert (device.read(0x00, 4), device.read(adxl355.REG_FILTER, 1), device.read(adxl355.REG_RANGE, 1)) == before


def test_reserved_codes_run_as_the_c_model_runs_them() -> None:
    """FILTER's reserved ODR_LPF codes (11…15) run at the slowest rate, 3.906 Hz, and RANGE's reserved code 0 at
    ±2 g, as the reference firmware's C model takes them: a part so configured makes samples, where a lookup of
    the part's tables used to fail in the middle of a request."""
    clock = VirtualClock()
    device = SimulatedAdxl355(VirtualLab(load_rig(SIM_RIG).model, clock, 5), 0)
    device.write(adxl355.REG_FILTER, 0x0F)
    device.write(adxl355.REG_RANGE, 0x80)
    device.write(adxl355.REG_POWER_CTL, 0x00)
    clock.sleep(10 / 3.906)
    codes, _ = adxl355.decode_fifo(device.read(adxl355.REG_FIFO_DATA, 288))
    assert codes.shape == (10, 3)
    assert np.linalg.norm(codes.mean(axis=0)) == pytest.approx(ADXL355.channel("accel").lsb_per_unit[2], rel=0.05)
