"""The bridge's reference firmware (firmware/) with an ICM-42688-P on its SPI: the host build in front of the C
model of the part (`bridge-host --part icm42688p`, firmware/host/icm42688_model.h), on a pseudo-terminal,
driven by the project's own ICM-42688-P driver (`Icm42688` over `SerialBridge`) as a board on a serial port
would be; and the SPI bytes the firmware sends for each request, as the host build records them
(`--spi-log`). The firmware finds the part by its WHO_AM_I at start and on every `?`, greets with protocol
version 3 and `part=icm42688p`, and frames `R`/`W` for it: a read is one command byte `addr | 0x80`, a write
`addr` then the value. It captures blocks of this part's FIFO packets (`capture=2304`, `C`/`G`), which the driver
set up; a block longer than that the driver reads from the FIFO itself. Runs on the board clock, as
test_bridge_firmware.py explains."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.core.clock import RealClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.instruments.adxl355_transport import SerialBridge
from accelcal_rig.instruments.icm42688_driver import Icm42688
from accelcal_rig.instruments.line_port import LinePort
from accelcal_rig.parts.icm42688 import ICM42688P
from tests.firmware.host_firmware import SEED, running

# The C model's facts (firmware/host/icm42688_model.h).
GRAVITY_UG = np.array([200_000, -400_000, 894_000])
RATE_MDPS = np.array([250, -150, 100])  # the part at rest, with a small zero-rate offset
ACCEL_NOISE_UG = 1000
GYRO_NOISE_MDPS = 200
GYRO_LSB_PER_10DPS = {2000: 164, 1000: 328, 500: 655, 250: 1310}  # the data sheet's LSB/(°/s), times 10
TEMPERATURE_C = 31.0


def rounded_division(numerator: np.ndarray, denominator: int) -> np.ndarray:
    """numerator / denominator rounded to the nearest integer, halves away from zero (the model's rounding)."""
    magnitude = (np.abs(numerator) + denominator // 2) // denominator
    return np.sign(numerator) * magnitude


def model_samples(count: int, accel_g: int, gyro_dps: int) -> tuple[np.ndarray, np.ndarray]:
    """(accel codes, gyro codes), each (count, 3), of the model's samples 0 … count - 1 since the sensors came on:
    the signal in the range's LSB plus the lowbias32 hash of each data word's index (6k + 0…5) + SEED, reduced
    to ±amplitude."""
    x = (np.arange(6 * count, dtype=np.uint64) + SEED).astype(np.uint32)
    x ^= x >> np.uint32(16)
    x *= np.uint32(0x7FEB352D)
    x ^= x >> np.uint32(15)
    x *= np.uint32(0x846CA68B)
    x ^= x >> np.uint32(16)
    words = x.reshape(-1, 6)
    accel_lsb = int(ICM42688P.channel("accel").lsb_per_unit[accel_g])
    gyro_lsb = GYRO_LSB_PER_10DPS[gyro_dps]
    accel_amplitude = int(rounded_division(np.array(ACCEL_NOISE_UG * accel_lsb), 1_000_000))
    gyro_amplitude = int(rounded_division(np.array(GYRO_NOISE_MDPS * gyro_lsb), 10_000))
    accel_noise = (words[:, :3] % np.uint32(2 * accel_amplitude + 1)).astype(np.int64) - accel_amplitude
    gyro_noise = (words[:, 3:] % np.uint32(2 * gyro_amplitude + 1)).astype(np.int64) - gyro_amplitude
    accel = rounded_division(GRAVITY_UG * accel_lsb, 1_000_000) + accel_noise
    gyro = rounded_division(RATE_MDPS * gyro_lsb, 10_000) + gyro_noise
    return accel.astype(np.int32), gyro.astype(np.int32)


def model_indices(accel: np.ndarray, gyro: np.ndarray, accel_g: int, gyro_dps: int, search: int = 20_000,
                  window: int = 100) -> np.ndarray:
    """Which of the model's samples each row of a block is, each found after the one before (within `window`
    samples of it); the test fails if a row is none of them (a corrupt byte, a sample from before, a repeat)."""
    model_accel, model_gyro = model_samples(search + window, accel_g, gyro_dps)
    model = np.concatenate([model_accel, model_gyro], axis=1)
    block = np.concatenate([accel, gyro], axis=1)
    indices = []
    after = 0
    for row_number, row in enumerate(block):
        stop = search if row_number == 0 else after + window
        hits = np.flatnonzero((model[after:stop] == row).all(axis=1))
        assert hits.size, f"sample {row_number} of the block is not one of the model's samples after the one before"
        indices.append(after + int(hits[0]))
        after = indices[-1] + 1
    return np.array(indices)


@dataclass
class Opened:
    driver: Icm42688
    bridge: SerialBridge


@contextmanager
def opened(binary: Path, *options: str) -> Iterator[Opened]:
    """The project's ICM-42688-P driver on the firmware's port, on the wall clock."""
    with running(binary, "--part", "icm42688p", "--temperature-c", str(TEMPERATURE_C), *options) as firmware:
        bridge = SerialBridge.open(firmware.path)
        try:
            yield Opened(Icm42688(bridge, "FW-IMU-1", RealClock()), bridge)
        finally:
            bridge.close()


@pytest.fixture
def imu(bridge_host: Path) -> Iterator[Opened]:
    with opened(bridge_host) as found:
        yield found


@contextmanager
def logged_line(binary: Path, log: Path, part: str) -> Iterator[LinePort]:
    """The bare line to the firmware in front of `part`, with every SPI transaction appended to `log`."""
    with running(binary, "--part", part, "--spi-log", str(log)) as firmware:
        port = LinePort.open(firmware.path, "bridge", 921600, 1.0)
        try:
            yield port
        finally:
            port.close()


class SpiLog:
    """The host build's record of SPI transactions (`--spi-log`): one line each, `<sent hex>:<received hex>`."""

    def __init__(self, path: Path) -> None:
        self._path = path
        self._seen = 0

    def new(self) -> list[str]:
        """The transactions since the last call (the firmware flushes each before it replies)."""
        lines = self._path.read_text().splitlines()
        fresh, self._seen = lines[self._seen:], len(lines)
        return fresh


def test_the_greeting_offers_a_capture_of_2304_packets_once_the_fifo_is_set_up(imu: Opened) -> None:
    """The firmware found the part by WHO_AM_I and offers its capture: 36 kB of 16-byte packets. A capture needs
    the sensors measuring and the FIFO in packets of both, which the driver's set-up gives it."""
    assert imu.bridge.part_name == "icm42688p"
    assert imu.bridge.capture_capacity_samples == 2304
    with pytest.raises(InstrumentError, match=r"'C 100' refused: capture needs the part measuring"):
        imu.bridge.start_capture(100)
    imu.bridge.write(regs.REG_PWR_MGMT0, regs.PWR_MGMT0_LOW_NOISE)
    with pytest.raises(InstrumentError, match=r"'C 100' refused: capture needs the FIFO on with both sensors "
                                              r"\(FIFO_CONFIG 00, FIFO_CONFIG1 00\)"):
        imu.bridge.start_capture(100)
    with pytest.raises(InstrumentError, match=r"'G 0' refused: no capture"):
        imu.bridge.fetch_capture(0)


def test_identity_reset_configure_and_read_back(imu: Opened) -> None:
    """The driver's bring-up through the firmware: WHO_AM_I, soft reset (RESET_DONE comes 1 ms later in the
    model, awaited by the driver), both CONFIG0 registers written and read back, the reset values after a
    reset, and the temperature."""
    driver, bridge = imu.driver, imu.bridge
    assert ICM42688P.wrong_identity(driver.identify().registers) is None
    driver.reset()
    driver.standby()
    driver.configure({"accel": 8, "gyro": 250}, 200.0)
    assert driver.read_settings() == ({"gyro": 250, "accel": 8}, 200.0)
    assert bridge.read(regs.REG_GYRO_CONFIG0, 2) == bytes([0x67, 0x27])
    driver.configure({"accel": 2, "gyro": 2000}, 100.0)
    assert driver.read_settings() == ({"gyro": 2000, "accel": 2}, 100.0)
    driver.reset()
    assert bridge.read(regs.REG_GYRO_CONFIG0, 2) == b"\x06\x06"  # both at their reset values (1 kHz, FS_SEL 0)
    assert bridge.read(regs.REG_PWR_MGMT0, 1) == b"\x00"
    assert driver.read_temperature_c() == pytest.approx(TEMPERATURE_C, abs=0.02)  # 1 LSB is 0.0075 °C


def bring_up(driver: Icm42688, odr_hz: float) -> None:
    driver.reset()
    driver.standby()
    driver.configure({"accel": 2, "gyro": 2000}, odr_hz)
    driver.start_measurement()


def assert_the_models_consecutive_samples(accel: np.ndarray, gyro: np.ndarray) -> None:
    """Every sample one the model made, each the one after the one before (none lost, none read twice), both
    channels decoding to the model's gravity and its near-zero rate."""
    indices = model_indices(accel, gyro, 2, 2000)
    assert np.all(np.diff(indices) == 1)
    accel_g = accel / ICM42688P.channel("accel").lsb_per_unit[2]
    gyro_dps = gyro / ICM42688P.channel("gyro").lsb_per_unit[2000]
    np.testing.assert_allclose(accel_g.mean(axis=0), GRAVITY_UG * 1e-6, atol=4e-4)  # noise ±1 mg: σ 0.07 mg over 60
    assert np.linalg.norm(accel_g.mean(axis=0)) == pytest.approx(1.0, abs=0.01)
    np.testing.assert_allclose(gyro_dps.mean(axis=0), RATE_MDPS * 1e-3, atol=0.1)
    assert np.all(np.abs(gyro_dps) < 0.5)  # at rest: the offset and the noise, no rotation


def test_a_block_the_bridge_captures_is_the_models_consecutive_samples(imu: Opened) -> None:
    """60 samples at 100 Hz captured by the firmware from the FIFO (packet 3, header checked): every one the model
    made, consecutive (gap-free whatever the host's latency: the bridge drains the FIFO), and the temperatures the
    model's, read as TEMP_DATA when the capture starts and ends."""
    bring_up(imu.driver, 100.0)
    block = imu.driver.acquire(60)
    assert block.codes["accel"].shape == block.codes["gyro"].shape == (60, 3)
    assert_the_models_consecutive_samples(block.codes["accel"], block.codes["gyro"])
    assert block.temperature_c == pytest.approx((TEMPERATURE_C, TEMPERATURE_C), abs=0.02)


def test_a_block_the_host_reads_from_the_fifo_is_the_models_consecutive_samples(imu: Opened) -> None:
    """The same through `R` alone (as for a block longer than the capture, or a bridge without one): the FIFO
    flushed, its count and whole packets read in bursts of 18 every 64 samples; 150 samples at 100 Hz, so the
    count crosses the burst size and the read interval."""
    imu.bridge.capture_capacity_samples = 0  # the driver asks the transport whether it captures
    bring_up(imu.driver, 100.0)
    block = imu.driver.acquire(150)
    assert block.codes["accel"].shape == (150, 3)
    assert_the_models_consecutive_samples(block.codes["accel"], block.codes["gyro"])


def test_the_spi_bytes_of_an_icm42688p_read_and_write(bridge_host: Path, tmp_path: Path) -> None:
    """What goes out on SPI: the probe at start is one WHO_AM_I read in the ICM framing (0x75 | 0x80 = 0xF5),
    and nothing in the ADXL355's framing reaches the part once it answered; `R` is one command byte
    `addr | 0x80` then the burst, `W` is `addr` then the value; `?` selects bank 0 before it looks again."""
    log = SpiLog(tmp_path / "spi.log")
    with logged_line(bridge_host, tmp_path / "spi.log", "icm42688p") as line:
        assert log.new() == ["F5:47"]
        assert line.ask("R 75 1") == "=47"
        assert log.new() == ["F5:47"]
        assert line.ask("W 4E 0F") == "="
        assert log.new() == ["4E0F:"]
        reply = line.ask("R 1D 17")
        sent, received = log.new()[0].split(":")
        assert (sent, "=" + received) == ("9D", reply) and len(received) == 34
        assert line.ask("W 76 01") == "="  # bank 1, where WHO_AM_I is not: the model reads 0 there
        assert line.ask("R 75 1") == "=00"
        log.new()
        assert line.ask("?").startswith("ADXL355-BRIDGE 3 part=icm42688p ")
        assert log.new() == ["7600:", "F5:47"]
        assert line.ask("R 75 1") == "=47"
        log.new()
        assert line.ask("C 10") == "!capture needs the FIFO on with both sensors (FIFO_CONFIG 00, FIFO_CONFIG1 00)"
        assert log.new() == ["CE:0F", "96:00", "DF:00"]  # PWR_MGMT0, FIFO_CONFIG, FIFO_CONFIG1 read; nothing written
        assert line.ask("W 5F 07") == "=" and line.ask("W 16 80") == "="
        log.new()
        assert line.ask("C 10").startswith("=")
        flush, status, temperature = log.new()[3:6]
        assert flush == "4B02:"                         # FIFO_FLUSH
        assert status.startswith("AD:") and len(status) == 3 + 6   # INT_STATUS, FIFO_COUNTH, FIFO_COUNTL in one burst
        assert temperature.startswith("9D:")            # TEMP_DATA1, TEMP_DATA0


def test_the_spi_bytes_of_an_adxl355_are_as_before(bridge_host: Path, tmp_path: Path) -> None:
    """With an ADXL355 the probe reads its register 0x7A (the ICM framing's WHO_AM_I read, harmless there), then
    DEVID_AD in its own framing; `R` and `W` keep the ADXL355's framing: `(addr << 1) | 1` and `addr << 1`."""
    log = SpiLog(tmp_path / "spi.log")
    with logged_line(bridge_host, tmp_path / "spi.log", "adxl355") as line:
        assert log.new() == ["F5:00", "01:AD"]
        assert line.ask("R 00 4") == "=AD1DED01"
        assert log.new() == ["01:AD1DED01"]
        assert line.ask("W 1F 07") == "="
        assert log.new() == ["3E07:"]


def test_no_part_on_spi_greets_part_none_and_refuses_register_access(bridge_host: Path) -> None:
    """A board whose sensor is not wired (every byte reads 0) still greets, naming no part, and says why it
    refuses; the driver's identity check fails with that message."""
    with running(bridge_host, "--part", "none") as firmware:
        bridge = SerialBridge.open(firmware.path)
        try:
            assert bridge.part_name == "none" and bridge.capture_capacity_samples == 0
            with pytest.raises(InstrumentError, match=r"refused: no sensor on SPI"):
                Icm42688(bridge, "FW-IMU-2", RealClock()).identify()
        finally:
            bridge.close()
