"""The simulated ICM-42688-P: its register model against the data sheet's behaviour, its hidden truth for
both sensors, and the driver through a version 3 serial bridge on a pseudo-terminal."""

from __future__ import annotations

import re

import numpy as np
import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.core.earth import EARTH_RATE_DPS
from accelcal_rig.errors import InstrumentError
from accelcal_rig.fit.gyro_model import PARAMETER_NAMES as GYRO_PARAMETER_NAMES
from accelcal_rig.fit.gyro_model import distort_rate
from accelcal_rig.fit.sfem import distort
from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.instruments.adxl355_transport import SerialBridge
from accelcal_rig.instruments.icm42688_driver import Icm42688
from accelcal_rig.parts.icm42688 import ICM42688P
from accelcal_rig.sim.icm42688_bridge_server import SimulatedIcm42688Bridge
from accelcal_rig.sim.icm42688_registers import SimulatedIcm42688
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.truth import gyro_truth_for_serial, truth_for_serial
from tests.conftest import REPO, SIM_RIG

SIM_IMU_RIG = REPO / "configs" / "sim-imu.yaml"


def imu_lab(seed: int = 5) -> tuple[VirtualLab, VirtualClock]:
    clock = VirtualClock()
    return VirtualLab(load_rig(SIM_IMU_RIG).model, clock, seed), clock


def test_the_gyro_truth_has_its_own_seed_and_an_adxl_lab_draws_nothing_for_it() -> None:
    gyro, accel = gyro_truth_for_serial("IMU-A001").coefficients, truth_for_serial("IMU-A001").coefficients
    assert gyro.shape == (len(GYRO_PARAMETER_NAMES), 4) and accel.shape == (12, 4)
    assert not np.allclose(gyro[:3], accel[:3])
    np.testing.assert_array_equal(gyro_truth_for_serial("IMU-A001").coefficients,
                                  gyro_truth_for_serial("IMU-A001").coefficients)
    adxl_lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 5)
    assert all(d.gyro_truth is None for d in adxl_lab.duts)
    imu, _ = imu_lab()
    assert all(d.gyro_truth is not None for d in imu.duts)


def test_registers_identity_reset_and_config() -> None:
    lab, clock = imu_lab()
    device = SimulatedIcm42688(lab, 0)
    assert device.read(regs.REG_WHO_AM_I, 1) == b"\x47"
    assert device.read(regs.REG_INT_STATUS, 1)[0] & regs.INT_STATUS_RESET_DONE
    assert device.read(regs.REG_INT_STATUS, 1)[0] == 0                  # cleared by reading
    device.write(regs.REG_GYRO_CONFIG0, 0x08)
    device.write(regs.REG_ACCEL_CONFIG0, 0x68)
    assert device.read(regs.REG_GYRO_CONFIG0, 2) == b"\x08\x68"
    device.write(regs.REG_WHO_AM_I, 0)                                     # read-only: ignored
    assert device.read(regs.REG_WHO_AM_I, 1) == b"\x47"
    device.write(regs.REG_ACCEL_CONFIG0, 0x0C)                             # a low-power rate: the part takes it
    assert device.read(regs.REG_ACCEL_CONFIG0, 1) == b"\x0c"
    device.write(regs.REG_DEVICE_CONFIG, regs.DEVICE_CONFIG_SOFT_RESET)
    assert device.read(regs.REG_GYRO_CONFIG0, 2) == b"\x06\x06"          # reset values
    assert device.read(regs.REG_INT_STATUS, 1)[0] & regs.INT_STATUS_RESET_DONE
    device.write(regs.REG_BANK_SEL, 1)                                     # banks 1…4 are not modelled
    assert device.read(regs.REG_WHO_AM_I, 2) == b"\x00\x01"               # they read 0, but REG_BANK_SEL
    device.write(regs.REG_GYRO_CONFIG0, 0x08)                              # and ignore writes
    device.write(regs.REG_BANK_SEL, 0)
    assert device.read(regs.REG_GYRO_CONFIG0, 1) == b"\x06"


def test_rates_and_ranges_the_part_does_not_offer_still_make_samples() -> None:
    """A low-power ODR code, the reserved ODR code 0 and a reserved accelerometer FS_SEL, as the reference
    firmware's C model takes them (6.25 Hz; 1 kHz; ±16 g): samples come, where a lookup of the part's table would
    have failed on the request."""
    lab, clock = imu_lab()
    device = SimulatedIcm42688(lab, 0)
    for accel_config0, period_s in ((0x6C, 1 / 6.25), (0xE0, 1e-3)):
        device.write(regs.REG_ACCEL_CONFIG0, accel_config0)
        device.write(regs.REG_PWR_MGMT0, regs.PWR_MGMT0_LOW_NOISE)
        clock.sleep(1.5 * period_s)
        _, accel, gyro = regs.decode_samples(device.read(regs.REG_TEMP_DATA1, regs.SAMPLE_BYTES))
        assert np.all(accel != regs.DATA_INVALID) and np.all(gyro != regs.DATA_INVALID)
        device.write(regs.REG_PWR_MGMT0, regs.PWR_MGMT0_OFF)


def test_data_registers_hold_a_new_sample_each_period_with_data_ready() -> None:
    lab, clock = imu_lab()
    device = SimulatedIcm42688(lab, 0)
    device.write(regs.REG_GYRO_CONFIG0, 0x08)      # ±2000 °/s, 100 Hz
    device.write(regs.REG_ACCEL_CONFIG0, 0x68)     # ±2 g, 100 Hz
    _, accel, gyro = regs.decode_samples(device.read(regs.REG_TEMP_DATA1, regs.SAMPLE_BYTES))
    assert np.all(accel == regs.DATA_INVALID) and np.all(gyro == regs.DATA_INVALID)   # off
    device.write(regs.REG_PWR_MGMT0, regs.PWR_MGMT0_LOW_NOISE)
    assert not device.read(regs.REG_INT_STATUS, 1)[0] & regs.INT_STATUS_DATA_RDY     # no sample yet
    clock.sleep(0.01)
    first = device.read(regs.REG_TEMP_DATA1, regs.SAMPLE_AND_STATUS_BYTES)
    assert first[-1] & regs.INT_STATUS_DATA_RDY
    again = device.read(regs.REG_TEMP_DATA1, regs.SAMPLE_AND_STATUS_BYTES)
    assert again[2:14] == first[2:14] and not again[-1] & regs.INT_STATUS_DATA_RDY   # the same sample
    clock.sleep(0.01)
    assert device.read(regs.REG_TEMP_DATA1, regs.SAMPLE_AND_STATUS_BYTES)[-1] & regs.INT_STATUS_DATA_RDY


def measuring_with_fifo(lab: VirtualLab, mode: int = regs.FIFO_MODE_STOP_ON_FULL) -> SimulatedIcm42688:
    """DUT 0 at ±2 g, ±2000 °/s, 100 Hz, its FIFO on in packets (in `mode`), measuring from now."""
    device = SimulatedIcm42688(lab, 0)
    device.write(regs.REG_GYRO_CONFIG0, 0x08)
    device.write(regs.REG_ACCEL_CONFIG0, 0x68)
    device.write(regs.REG_FIFO_CONFIG1, regs.FIFO_CONFIG1_ACCEL_GYRO_TEMP)
    device.write(regs.REG_FIFO_CONFIG, mode)
    device.write(regs.REG_PWR_MGMT0, regs.PWR_MGMT0_LOW_NOISE)
    return device


def fifo_count(device: SimulatedIcm42688) -> tuple[int, int]:
    """(INT_STATUS, FIFO_COUNT in bytes) in one burst from INT_STATUS, as the driver reads them."""
    status, high, low = device.read(regs.REG_INT_STATUS, 3)
    return status, high << 8 | low


def test_the_fifo_fills_with_a_packet_of_both_sensors_each_period() -> None:
    lab, clock = imu_lab()
    device = SimulatedIcm42688(lab, 0)
    assert device.read(regs.REG_INTF_CONFIG0, 1) == b"\x30"          # counts in bytes, big-endian
    device = measuring_with_fifo(lab)
    clock.sleep(0.035)
    assert fifo_count(device)[1] == 3 * 16
    accel, gyro, temperature = regs.decode_packets(device.read(regs.REG_FIFO_DATA, 48))
    assert accel.shape == gyro.shape == (3, 3)
    assert np.all(np.abs(accel[:, 2] - 16384) < 2000)                  # about 1 g on some axis, no invalid code
    assert np.all(temperature == temperature[0])
    assert fifo_count(device)[1] == 0
    assert device.read(regs.REG_FIFO_DATA, 16) == b"\xff" * 16         # empty: header bit 7 set
    packet = device.read(regs.REG_FIFO_DATA, 1)
    assert packet == b"\xff"
    clock.sleep(0.02)
    raw = device.read(regs.REG_FIFO_DATA, 32)
    first_ts, second_ts = (int.from_bytes(raw[i * 16 + 14:i * 16 + 16], "big") for i in range(2))
    assert second_ts - first_ts == round(10_000 * 30 / 32)             # the timestamp: 30/32 µs ticks per µs


def test_a_full_fifo_stops_sets_fifo_full_and_a_flush_empties_it() -> None:
    lab, clock = imu_lab()
    device = measuring_with_fifo(lab)
    clock.sleep(1.275)                                                  # 127 samples
    status, count = fifo_count(device)
    assert count == 127 * 16 and not status & regs.INT_STATUS_FIFO_FULL
    clock.sleep(0.05)
    status, count = fifo_count(device)
    assert count == 2048 and status & regs.INT_STATUS_FIFO_FULL        # stop-on-full: the newest dropped
    assert not fifo_count(device)[0] & regs.INT_STATUS_FIFO_FULL       # cleared by reading INT_STATUS
    first = device.read(regs.REG_FIFO_DATA, 16)
    assert int.from_bytes(first[14:16], "big") == round(10_000 * 30 / 32)   # the oldest, sample 1, kept
    device.write(regs.REG_SIGNAL_PATH_RESET, regs.SIGNAL_PATH_RESET_FIFO_FLUSH)
    assert fifo_count(device)[1] == 0
    assert device.read(regs.REG_SIGNAL_PATH_RESET, 1) == b"\x00"      # its bits clear themselves


def test_in_stream_mode_a_full_fifo_keeps_the_newest() -> None:
    lab, clock = imu_lab()
    device = measuring_with_fifo(lab, mode=0x40)
    clock.sleep(1.505)                                                  # 150 samples
    status, count = fifo_count(device)
    assert count == 2048 and status & regs.INT_STATUS_FIFO_FULL
    first = device.read(regs.REG_FIFO_DATA, 16)
    assert int.from_bytes(first[14:16], "big") == (round(23 * 10_000 * 30 / 32) & 0xFFFF)  # 22 dropped


def test_a_fifo_that_is_off_or_a_sensor_that_is_off_fills_nothing() -> None:
    lab, clock = imu_lab()
    device = measuring_with_fifo(lab, mode=regs.FIFO_MODE_BYPASS)
    clock.sleep(0.1)
    assert fifo_count(device)[1] == 0
    device.write(regs.REG_FIFO_CONFIG, regs.FIFO_MODE_STOP_ON_FULL)
    device.write(regs.REG_PWR_MGMT0, regs.PWR_MGMT0_OFF)
    clock.sleep(0.1)
    assert fifo_count(device)[1] == 0


def test_the_bridge_captures_packets_and_refuses_a_fifo_that_is_off() -> None:
    lab, clock = imu_lab()
    bridge = SimulatedIcm42688Bridge(lab, 0)
    answer = bridge._requests.answer  # noqa: SLF001 - the request handler, without a pseudo-terminal
    assert answer("?") == "ADXL355-BRIDGE 3 part=icm42688p capture=2304 accelcal-rig simulated bridge"
    for request in ("W 4F 08", "W 50 68", "W 4E 0F"):
        assert answer(request) == "="
    assert answer("C 10") == "!capture needs the FIFO on with both sensors (FIFO_CONFIG 00, FIFO_CONFIG1 00)"
    for request in ("W 5F 07", "W 16 80"):
        assert answer(request) == "="
    assert answer("C 10").startswith("=") and len(answer("C 10")) == 5
    assert answer("R 30 16") == "!FIFO_DATA is being captured (fetch with G)"
    assert answer("R 2D 4") == "!FIFO_DATA is being captured (fetch with G)"
    assert answer("R 1D 16").startswith("=")                             # the data registers are the host's
    clock.sleep(0.055)
    partial = answer("G 0")
    assert len(partial) == 1 + 5 * 32 and "T" not in partial
    clock.sleep(0.05)
    complete = answer("G 3")
    assert len(complete) == 1 + 7 * 32 + 5 and complete[-5] == "T"
    accel, _, _ = regs.decode_packets(bytes.fromhex(complete[1:-5]))
    assert accel.shape == (7, 3)
    assert answer("C 100").startswith("=")
    clock.sleep(0.125)
    assert answer("W 4E 00") == "="
    assert re.fullmatch(r"!capture stopped: register 0x4E written after 1[23] of 100 samples", answer("G 0"))


def connected(lab: VirtualLab, clock: VirtualClock, index: int = 0):
    server = SimulatedIcm42688Bridge(lab, index).start()
    bridge = SerialBridge.open(server.path)
    return Icm42688(bridge, lab.duts[index].serial, clock, ICM42688P), bridge, server


def test_the_driver_through_a_version_3_bridge_reads_both_sensors_truth() -> None:
    lab, clock = imu_lab(seed=7)
    driver, bridge, server = connected(lab, clock)
    try:
        assert bridge.part_name == "icm42688p" and bridge.capture_capacity_samples == 2304
        assert ICM42688P.wrong_identity(driver.identify().registers) is None
        driver.reset()
        driver.standby()
        driver.configure({"accel": 2, "gyro": 2000}, 100)
        driver.start_measurement()
        assert driver.read_settings() == ({"gyro": 2000, "accel": 2}, 100.0)
        block = clock.run_concurrently([lambda: driver.acquire(400)])[0]
    finally:
        driver.close()
        server.stop()
    accel, gyro = block.codes["accel"], block.codes["gyro"]
    assert accel.shape == gyro.shape == (400, 3)
    assert block.t_end_s - block.t_start_s == pytest.approx(3.99)
    assert len({tuple(row) for row in accel}) > 300                  # a new sample each packet
    dut = lab.duts[0]
    temperature = lab.dut_true_c(0)
    # The accelerometer sees gravity through its own truth (noise 70 µg/√Hz × √(π/2·25 Hz) ≈ 0.44 mg).
    expected_g = distort(lab.gravity_in_dut(0), dut.truth.parameters_at(temperature))
    assert accel.mean(axis=0) / 16384 == pytest.approx(expected_g, abs=3e-4)
    assert accel.std(axis=0, ddof=1).mean() / 16384 == pytest.approx(70e-6 * np.sqrt(np.pi / 2 * 25), rel=0.25)
    # The gyroscope at rest reads its hidden bias, the Earth's rate and its g-sensitivity to gravity through its
    # own truth, in its own range's codes (noise 2.8 mdps/√Hz × √(π/2·25 Hz) and the 0.061 °/s code: ≤ 0.01 °/s).
    parameters = dut.gyro_truth.parameters_at(temperature)
    bias_dps = parameters[:3]
    earth_dps = lab.true_rate_dps(0)
    assert np.linalg.norm(earth_dps) == pytest.approx(EARTH_RATE_DPS, rel=1e-9)   # the table at rest
    expected_dps = distort_rate(earth_dps, lab.gravity_in_dut(0), parameters)
    assert gyro.mean(axis=0) / 16.4 == pytest.approx(expected_dps, abs=0.01)
    assert np.all(np.abs(bias_dps) < 1.0) and np.any(np.abs(bias_dps) > 0.05)
    assert block.temperature_c[0] == pytest.approx(temperature, abs=0.2)


def test_a_block_longer_than_the_capture_is_read_from_the_fifo_by_the_host() -> None:
    lab, clock = imu_lab(seed=3)
    driver, _, server = connected(lab, clock)
    try:
        driver.reset()
        driver.configure({"accel": 2, "gyro": 2000}, 100)
        driver.start_measurement()
        block = clock.run_concurrently([lambda: driver.acquire(4200)])[0]
    finally:
        driver.close()
        server.stop()
    assert block.codes["accel"].shape == block.codes["gyro"].shape == (4200, 3)
    assert len({tuple(row) for row in block.codes["accel"]}) > 3500   # new noise in each (7 LSB on each axis)
    assert block.t_end_s - block.t_start_s == pytest.approx(41.99)


def test_a_wrong_who_am_i_is_what_the_identity_check_catches() -> None:
    lab, clock = imu_lab()
    server = SimulatedIcm42688Bridge(lab, 1, wrong_who_am_i=True).start()
    bridge = SerialBridge.open(server.path)
    driver = Icm42688(bridge, "IMU-A002", clock, ICM42688P)
    try:
        assert "is not an ICM-42688-P (47)" in ICM42688P.wrong_identity(driver.identify().registers)
        with pytest.raises(InstrumentError, match="refused: read-only register 0x75"):
            bridge.write(regs.REG_WHO_AM_I, 0)
    finally:
        driver.close()
        server.stop()
