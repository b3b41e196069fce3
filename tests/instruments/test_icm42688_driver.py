"""The ICM-42688-P driver, byte for byte: every register access it makes, in order, against a scripted
transport on the virtual clock (no wire, no simulator: the register traffic is the specification)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.instruments.icm42688_driver import GYRO_STARTUP_S, Icm42688
from accelcal_rig.parts.icm42688 import ICM42688P


class ScriptedBus:
    """A RegisterTransport that expects exactly the accesses of its script, in order, and answers reads with
    the script's bytes; `at` records the clock time of each access, `during` runs an action inside one."""

    endpoint = "scripted"
    capture_capacity_samples = 0

    def __init__(self, clock: VirtualClock, script: list[tuple]) -> None:
        self._clock = clock
        self._script = list(script)
        self.at: list[float] = []
        self.during: dict[int, Callable[[], None]] = {}

    def _next(self, access: tuple) -> tuple:
        assert self._script, f"unexpected {access}: the script has ended"
        expected = self._script.pop(0)
        assert expected[:3] == access, f"access {len(self.at)}: expected {expected[:3]}, got {access}"
        self.at.append(self._clock.now())
        if len(self.at) - 1 in self.during:
            self.during[len(self.at) - 1]()
        return expected

    def read(self, address: int, count: int) -> bytes:
        reply = self._next(("R", address, count))[3]
        assert len(reply) == count
        return reply

    def write(self, address: int, value: int) -> None:
        self._next(("W", address, value))

    def close(self) -> None:
        pass

    @property
    def done(self) -> bool:
        return not self._script


def driver_on(script: list[tuple]) -> tuple[Icm42688, ScriptedBus, VirtualClock]:
    clock = VirtualClock()
    bus = ScriptedBus(clock, script)
    return Icm42688(bus, "IMU-A001", clock, ICM42688P), bus, clock


def burst(temperature: int, accel: tuple[int, int, int], gyro: tuple[int, int, int], status: int) -> bytes:
    """What R 1D 17 answers: the 14 data bytes, TMST_FSYNCH/L, INT_STATUS."""
    return regs.encode_sample(temperature, np.array(accel), np.array(gyro)) + b"\x00\x00" + bytes([status])


def test_the_addresses_are_the_data_sheets() -> None:
    assert (regs.REG_TEMP_DATA1, regs.REG_ACCEL_DATA_X1, regs.REG_GYRO_DATA_X1, regs.REG_GYRO_DATA_Z0) == \
        (0x1D, 0x1F, 0x25, 0x2A)
    assert (regs.REG_INT_STATUS, regs.REG_PWR_MGMT0, regs.REG_GYRO_CONFIG0, regs.REG_ACCEL_CONFIG0) == \
        (0x2D, 0x4E, 0x4F, 0x50)
    assert (regs.REG_DEVICE_CONFIG, regs.REG_WHO_AM_I, regs.REG_BANK_SEL) == (0x11, 0x75, 0x76)
    assert (regs.SAMPLE_BYTES, regs.SAMPLE_AND_STATUS_BYTES) == (14, 17)


def test_identify_selects_bank_0_then_reads_who_am_i() -> None:
    driver, bus, _ = driver_on([("W", 0x76, 0x00), ("R", 0x75, 1, b"\x47")])
    identity = driver.identify()
    assert identity.registers == (0x47,) and ICM42688P.wrong_identity(identity.registers) is None
    assert identity.revision is None and identity.describe(ICM42688P.label) == "ICM-42688-P"  # no revision register
    assert bus.done


def test_reset_waits_for_reset_done_on_the_clock() -> None:
    driver, bus, clock = driver_on([("W", 0x76, 0x00), ("W", 0x11, 0x01),
                                    ("R", 0x2D, 1, b"\x00"), ("R", 0x2D, 1, b"\x00"), ("R", 0x2D, 1, b"\x10")])
    driver.reset()
    assert bus.done
    assert bus.at[2:] == pytest.approx([0.0, 0.001, 0.002])


def test_a_reset_that_never_completes_is_a_fault_within_its_deadline() -> None:
    driver, _, clock = driver_on([("W", 0x76, 0x00), ("W", 0x11, 0x01)] + [("R", 0x2D, 1, b"\x00")] * 101)
    with pytest.raises(InstrumentError, match="RESET_DONE after soft reset: not reached within"):
        driver.reset()
    assert clock.now() == pytest.approx(0.1)


@pytest.mark.parametrize(("ranges", "odr_hz", "gyro", "accel"), [
    ({"accel": 2, "gyro": 2000}, 100, 0x08, 0x68),       # FS_SEL 0 / 3, ODR code 8
    ({"accel": 16, "gyro": 15.625}, 1000, 0xE6, 0x06),   # FS_SEL 7 / 0, ODR code 6
    ({"accel": 4.0, "gyro": 250.0}, 500, 0x6F, 0x4F),    # floats from a procedure; 500 Hz is code 15
])
def test_configure_writes_both_config0_registers_and_reads_them_back(ranges, odr_hz, gyro, accel) -> None:
    driver, bus, _ = driver_on([("W", 0x4F, gyro), ("W", 0x50, accel), ("R", 0x4F, 2, bytes([gyro, accel]))])
    driver.configure(ranges, odr_hz)
    assert bus.done


def test_a_configuration_that_does_not_read_back_is_a_fault() -> None:
    driver, _, _ = driver_on([("W", 0x4F, 0x08), ("W", 0x50, 0x68), ("R", 0x4F, 2, b"\x08\x66")])
    with pytest.raises(InstrumentError, match="read back 08/66, not 08/68"):
        driver.configure({"accel": 2, "gyro": 2000}, 100)


def test_configure_needs_every_channels_range() -> None:
    driver, bus, _ = driver_on([])
    with pytest.raises(InstrumentError, match="no range given for its gyro channel"):
        driver.configure({"accel": 2}, 100)


def test_start_and_standby_write_pwr_mgmt0() -> None:
    driver, bus, clock = driver_on([("W", 0x4E, 0x0F), ("W", 0x4E, 0x00)])
    driver.start_measurement()
    assert clock.now() == pytest.approx(GYRO_STARTUP_S)   # the gyroscope's start-up, on the clock
    driver.standby()
    assert bus.done


def test_read_settings_decodes_both_registers() -> None:
    driver, _, _ = driver_on([("R", 0x4F, 2, b"\xE6\x06")])
    assert driver.read_settings() == ({"gyro": 15.625, "accel": 16}, 1000.0)


@pytest.mark.parametrize(("reply", "expected"), [
    (b"\x08\x67", "different rates"),
    (b"\x0C\x6C", "GYRO_CONFIG0 reads 0x0C: no range or rate"),   # ODR code 12: low-power only
])
def test_settings_that_are_no_configuration_of_the_part_are_faults(reply: bytes, expected: str) -> None:
    driver, _, _ = driver_on([("R", 0x4F, 2, reply)])
    with pytest.raises(InstrumentError, match=expected):
        driver.read_settings()


def test_temperature_is_temp_data_over_132_48_plus_25() -> None:
    driver, _, _ = driver_on([("R", 0x1D, 2, (-2650).to_bytes(2, "big", signed=True)), ("R", 0x1D, 2, b"\x80\x00")])
    assert driver.read_temperature_c() == pytest.approx(25 - 2650 / 132.48)
    with pytest.raises(InstrumentError, match="TEMP_DATA holds no reading"):
        driver.read_temperature_c()


def configured(script: list[tuple]) -> tuple[Icm42688, ScriptedBus, VirtualClock]:
    """A driver set to 100 Hz, then `script`."""
    driver, bus, clock = driver_on([("W", 0x4F, 0x08), ("W", 0x50, 0x68), ("R", 0x4F, 2, b"\x08\x68"), *script])
    driver.configure({"accel": 2, "gyro": 2000}, 100)
    return driver, bus, clock


def test_acquire_reads_one_burst_per_sample_at_the_rate_and_rereads_a_stale_one() -> None:
    stale = burst(100, (1, 2, 16384), (3, 4, 5), 0x00)
    driver, bus, clock = configured([
        ("R", 0x1D, 17, stale),                                           # clears DATA_RDY
        ("R", 0x1D, 17, burst(100, (10, -20, 16380), (1, -1, 2), 0x08)),
        ("R", 0x1D, 17, burst(101, (11, -21, 16381), (1, -1, 2), 0x00)),  # not new yet: again in T/8
        ("R", 0x1D, 17, burst(102, (12, -22, 16382), (2, -2, 3), 0x08)),
        ("R", 0x1D, 17, burst(-2650, (13, -23, 16383), (2, -2, 4), 0x18)),
    ])
    block = driver.acquire(3)
    assert bus.done
    # Paced from the block's first read (0.01): the third is due at 0.03, not a period after the re-read.
    assert bus.at[3:] == pytest.approx([0.0, 0.01, 0.02, 0.02125, 0.03])
    assert block.codes["accel"].tolist() == [[10, -20, 16380], [12, -22, 16382], [13, -23, 16383]]
    assert block.codes["gyro"].tolist() == [[1, -1, 2], [2, -2, 3], [2, -2, 4]]
    assert block.codes["accel"].dtype == np.int32
    assert (block.t_start_s, block.t_end_s) == pytest.approx((0.01, 0.03))
    assert block.temperature_c == pytest.approx((25 + 100 / 132.48, 25 - 2650 / 132.48))


def test_a_late_read_starts_the_block_again() -> None:
    fresh = burst(0, (0, 0, 16384), (0, 0, 0), 0x08)
    driver, bus, clock = configured([("R", 0x1D, 17, fresh)] * 2 + [("R", 0x1D, 17, fresh)] * 3)
    bus.during[4] = lambda: clock.sleep(0.02)   # the first sample's reply takes two periods
    block = driver.acquire(2)
    assert bus.done                              # the given-up block's two reads, then the new block's three
    assert bus.at[3:] == pytest.approx([0.0, 0.01, 0.03, 0.04, 0.05])
    assert block.t_start_s == pytest.approx(0.04)


def test_a_link_too_slow_for_the_rate_is_a_fault_naming_it() -> None:
    fresh = burst(0, (0, 0, 16384), (0, 0, 0), 0x08)
    driver, bus, clock = configured([("R", 0x1D, 17, fresh)] * 6)
    for access in (4, 6, 8):
        bus.during[access] = lambda: clock.sleep(0.02)
    with pytest.raises(InstrumentError, match="cannot poll 100 Hz"):
        driver.acquire(2)


def test_a_part_that_never_says_data_ready_is_a_fault() -> None:
    stale = burst(0, (0, 0, 16384), (0, 0, 0), 0x00)
    driver, _, _ = configured([("R", 0x1D, 17, stale)] * 17)
    with pytest.raises(InstrumentError, match="data-ready status never set"):
        driver.acquire(1)


def test_invalid_data_in_a_block_is_a_fault() -> None:
    fresh = burst(0, (-32768, 0, 0), (0, 0, 0), 0x08)
    driver, _, _ = configured([("R", 0x1D, 17, fresh)] * 2)
    with pytest.raises(InstrumentError, match="no reading"):
        driver.acquire(1)


def test_over_spidev_the_command_byte_is_framed_as_the_icm42688p_wants() -> None:
    """Mode 0 SPI, bit 7 set to read (WHO_AM_I 0x75 → 0xF5), clear to write (PWR_MGMT0 0x4E → 0x4E): the
    framing is the part's, not the ADXL355's (address << 1 | 1)."""
    from accelcal_rig.instruments.adxl355_transport import SpidevBus
    from accelcal_rig.parts.icm42688 import ICM42688P

    sent: list[list[int]] = []

    class Spi:
        def xfer2(self, data: list[int]) -> list[int]:
            sent.append(list(data))
            return [0, 0x47] if data[0] == 0xF5 else [0] * len(data)

        def close(self) -> None:
            pass

    bus = SpidevBus(Spi(), "spidev 0.1", ICM42688P.spi)
    assert bus.read(0x75, 1) == bytes([0x47])
    bus.write(0x4E, 0x0F)
    assert sent == [[0xF5, 0x00], [0x4E, 0x0F]]
