"""The ICM-42688-P driver, byte for byte: every register access it makes, in order, against a scripted
transport on the virtual clock (no wire, no simulator: the register traffic is the specification)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.instruments.icm42688_driver import BURST_PACKETS, GYRO_STARTUP_S, Icm42688
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


def packets(accel: list[tuple[int, int, int]], gyro: list[tuple[int, int, int]]) -> bytes:
    """What a burst of FIFO_DATA answers for these samples: packet 3 each (temperature 25 °C, timestamps 0, 1, …)."""
    n = len(accel)
    return regs.encode_packets(np.array(accel), np.array(gyro), np.zeros(n), np.arange(n))


def status_and_count(status: int, packet_count: int) -> bytes:
    """What R 2D 3 answers: INT_STATUS, FIFO_COUNTH, FIFO_COUNTL (bytes, big-endian)."""
    return bytes([status]) + (packet_count * 16).to_bytes(2, "big")


def temperature(code: int) -> bytes:
    return code.to_bytes(2, "big", signed=True)


def test_the_addresses_are_the_data_sheets() -> None:
    assert (regs.REG_TEMP_DATA1, regs.REG_ACCEL_DATA_X1, regs.REG_GYRO_DATA_X1, regs.REG_GYRO_DATA_Z0) == \
        (0x1D, 0x1F, 0x25, 0x2A)
    assert (regs.REG_INT_STATUS, regs.REG_PWR_MGMT0, regs.REG_GYRO_CONFIG0, regs.REG_ACCEL_CONFIG0) == \
        (0x2D, 0x4E, 0x4F, 0x50)
    assert (regs.REG_DEVICE_CONFIG, regs.REG_WHO_AM_I, regs.REG_BANK_SEL) == (0x11, 0x75, 0x76)
    assert (regs.SAMPLE_BYTES, regs.SAMPLE_AND_STATUS_BYTES) == (14, 17)
    assert (regs.REG_FIFO_CONFIG, regs.REG_FIFO_COUNTH, regs.REG_FIFO_DATA, regs.REG_SIGNAL_PATH_RESET,
            regs.REG_INTF_CONFIG0, regs.REG_FIFO_CONFIG1) == (0x16, 0x2E, 0x30, 0x4B, 0x4C, 0x5F)
    assert (regs.FIFO_BYTES, regs.PACKET_BYTES, regs.FIFO_PACKETS, regs.PACKET3_HEADER) == (2048, 16, 128, 0x68)


def test_a_packet_is_header_accel_gyro_temperature_timestamp_big_endian() -> None:
    """Packet 3 (DS-000347 §6.1): header 0x68, accelerometer X/Y/Z and gyroscope X/Y/Z high byte first, the 8-bit
    temperature (°C = T/2.07 + 25: 64 of TEMP_DATA's codes), the timestamp high byte first."""
    raw = regs.encode_packets(np.array([[1, -2, 16384]]), np.array([[-32768, 5, 300]]), np.array([64 * 10]),
                              np.array([0x1234]))
    assert raw.hex() == "68" "0001" "fffe" "4000" "8000" "0005" "012c" "0a" "1234"
    accel, gyro, temperature_codes = regs.decode_packets(raw)
    assert accel.tolist() == [[1, -2, 16384]] and gyro.tolist() == [[-32768, 5, 300]]
    assert temperature_codes.tolist() == [640]
    assert regs.decode_packets(bytes([0x6B]) + raw[1:])[0].tolist() == [[1, -2, 16384]]  # ODR-change bits ignored
    with pytest.raises(ValueError, match="packet 0 has header 0xFF"):
        regs.decode_packets(b"\xff" * 16)


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
def test_configure_writes_both_config0_registers_and_the_fifo_and_reads_them_back(ranges, odr_hz, gyro, accel) -> None:
    driver, bus, _ = driver_on([("W", 0x4F, gyro), ("W", 0x50, accel), ("R", 0x4F, 2, bytes([gyro, accel])),
                                *FIFO_SET_UP])
    driver.configure(ranges, odr_hz)
    assert bus.done


#: The FIFO's set-up: accelerometer, gyroscope and temperature in packets, stop-on-full, each read back.
FIFO_SET_UP = [("W", 0x5F, 0x07), ("W", 0x16, 0x80), ("R", 0x16, 1, b"\x80"), ("R", 0x5F, 1, b"\x07")]


def test_a_configuration_that_does_not_read_back_is_a_fault() -> None:
    driver, _, _ = driver_on([("W", 0x4F, 0x08), ("W", 0x50, 0x68), ("R", 0x4F, 2, b"\x08\x66")])
    with pytest.raises(InstrumentError, match="read back 08/66, not 08/68"):
        driver.configure({"accel": 2, "gyro": 2000}, 100)


def test_a_fifo_set_up_that_does_not_read_back_is_a_fault() -> None:
    driver, _, _ = driver_on([("W", 0x4F, 0x08), ("W", 0x50, 0x68), ("R", 0x4F, 2, b"\x08\x68"),
                              ("W", 0x5F, 0x07), ("W", 0x16, 0x80), ("R", 0x16, 1, b"\x00"), ("R", 0x5F, 1, b"\x07")])
    with pytest.raises(InstrumentError, match="FIFO_CONFIG/FIFO_CONFIG1 read back 00/07, not 80/07"):
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
    driver, bus, clock = driver_on([("W", 0x4F, 0x08), ("W", 0x50, 0x68), ("R", 0x4F, 2, b"\x08\x68"), *FIFO_SET_UP,
                                    *script])
    driver.configure({"accel": 2, "gyro": 2000}, 100)
    return driver, bus, clock


#: A block's start: the FIFO flushed, INT_STATUS and the count read (clearing a stale FIFO_FULL), TEMP_DATA.
def block_start(code: int = 100) -> list[tuple]:
    return [("W", 0x4B, 0x02), ("R", 0x2D, 3, status_and_count(0x02, 0)), ("R", 0x1D, 2, temperature(code))]


def test_acquire_flushes_the_fifo_then_reads_its_count_and_whole_packets() -> None:
    accel, gyro = [(10, -20, 16380), (11, -21, 16381), (12, -22, 16382)], [(1, -1, 2), (2, -2, 3), (2, -2, 4)]
    driver, bus, clock = configured([*block_start(100),
                                     ("R", 0x2D, 3, status_and_count(0x08, 3)), ("R", 0x30, 48, packets(accel, gyro)),
                                     ("R", 0x1D, 2, temperature(-2650))])
    block = driver.acquire(3)
    assert bus.done
    assert bus.at[7:] == pytest.approx([0.0, 0.0, 0.0, 0.03, 0.03, 0.03])  # read when three samples are in
    assert block.codes["accel"].tolist() == [list(a) for a in accel] and block.codes["gyro"].tolist() == [list(g) for g in gyro]
    assert block.codes["accel"].dtype == np.int32
    assert (block.t_start_s, block.t_end_s) == pytest.approx((0.0, 0.02))
    assert block.temperature_c == pytest.approx((25 + 100 / 132.48, 25 - 2650 / 132.48))


def test_a_long_block_is_read_in_bursts_of_whole_packets_every_64_samples() -> None:
    """The bridge reads 288 bytes at most: 18 packets a burst; the FIFO's 128 are read when half full."""
    samples = [(i, -i, 16384) for i in range(70)]
    rates = [(0, 0, i) for i in range(70)]
    script = [*block_start(), ("R", 0x2D, 3, status_and_count(0, 64))]
    for first in range(0, 64, BURST_PACKETS):
        n = min(BURST_PACKETS, 64 - first)
        script.append(("R", 0x30, 16 * n, packets(samples[first:first + n], rates[first:first + n])))
    script += [("R", 0x2D, 3, status_and_count(0, 6)), ("R", 0x30, 96, packets(samples[64:], rates[64:])),
               ("R", 0x1D, 2, temperature(100))]
    driver, bus, clock = configured(script)
    block = driver.acquire(70)
    assert bus.done
    assert block.codes["accel"].tolist() == [list(a) for a in samples]
    assert block.codes["gyro"].tolist() == [list(g) for g in rates]
    assert clock.now() == pytest.approx(0.70)


def test_a_full_fifo_takes_the_block_again_and_three_are_a_fault() -> None:
    full = [*block_start(), ("R", 0x2D, 3, status_and_count(0x02, 128))]
    accel, gyro = [(0, 0, 16384)] * 2, [(0, 0, 0)] * 2
    driver, bus, _ = configured([*full, *block_start(), ("R", 0x2D, 3, status_and_count(0, 2)),
                                 ("R", 0x30, 32, packets(accel, gyro)), ("R", 0x1D, 2, temperature(0))])
    assert driver.acquire(2).codes["accel"].tolist() == [[0, 0, 16384]] * 2
    assert bus.done
    driver, _, _ = configured(full * 3)
    with pytest.raises(InstrumentError, match="IMU-A001 .*FIFO full in 3 attempts: the link cannot keep up with 100 Hz"):
        driver.acquire(2)


def test_a_packet_out_of_step_is_a_fault_naming_its_header() -> None:
    driver, _, _ = configured([*block_start(), ("R", 0x2D, 3, status_and_count(0, 1)), ("R", 0x30, 16, b"\x80" * 16)])
    with pytest.raises(InstrumentError, match="IMU-A001 .*FIFO: FIFO packet 0 has header 0x80"):
        driver.acquire(1)


def test_invalid_data_in_a_block_is_a_fault() -> None:
    driver, _, _ = configured([*block_start(), ("R", 0x2D, 3, status_and_count(0, 1)),
                               ("R", 0x30, 16, packets([(-32768, -32768, -32768)], [(0, 0, 0)]))])
    with pytest.raises(InstrumentError, match="no reading"):
        driver.acquire(1)


def test_a_fifo_that_never_fills_is_a_fault_within_its_deadline() -> None:
    driver, _, clock = configured([*block_start()] + [("R", 0x2D, 3, status_and_count(0, 0))] * 40)
    with pytest.raises(InstrumentError, match="0 of 3 samples before the deadline: is it measuring"):
        driver.acquire(3)
    assert clock.now() <= 2.0 * 3 / 100 + 1.0 + 0.03 + 1e-9


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
