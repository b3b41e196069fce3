"""The LIS3MDL driver, byte for byte: every register access it makes, in order, against a scripted transport on
the virtual clock (the register traffic is the specification), and the SPI bytes the bridge sends for them."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments import lis3mdl as regs
from accelcal_rig.instruments.lis3mdl_driver import RESET_TIMEOUT_S, TURN_ON_S, Lis3mdl
from accelcal_rig.parts.lis3mdl import LIS3MDL
from tests.instruments.test_icm42688_driver import ScriptedBus


def driver_on(script: list[tuple]) -> tuple[Lis3mdl, ScriptedBus, VirtualClock]:
    clock = VirtualClock()
    bus = ScriptedBus(clock, script)
    return Lis3mdl(bus, "LIS3MDL-M001", clock, LIS3MDL), bus, clock


def sample(status: int, field: tuple[int, int, int], temperature: int) -> bytes:
    """What R 27 9 answers: STATUS, OUT_X_L … OUT_Z_H, TEMP_OUT_L/H, little-endian."""
    return bytes([status]) + regs.encode_words(np.array([*field, temperature]))


def test_the_addresses_are_the_data_sheets() -> None:
    assert (regs.REG_WHO_AM_I, regs.REG_CTRL1, regs.REG_CTRL2, regs.REG_CTRL3, regs.REG_CTRL4, regs.REG_CTRL5) == \
        (0x0F, 0x20, 0x21, 0x22, 0x23, 0x24)
    assert (regs.REG_STATUS, regs.REG_OUT_X_L, regs.REG_TEMP_OUT_L, regs.REG_INT_CFG, regs.REG_LAST) == \
        (0x27, 0x28, 0x2E, 0x30, 0x33)
    assert regs.SAMPLE_BYTES == 9
    assert regs.RESET_VALUES == {0x0F: 0x3D, 0x20: 0x10, 0x22: 0x03, 0x30: 0xE8}


def test_identify_reads_who_am_i() -> None:
    driver, bus, _ = driver_on([("R", 0x0F, 1, b"\x3d")])
    identity = driver.identify()
    assert identity.registers == (0x3D,) and LIS3MDL.wrong_identity(identity.registers) is None
    assert bus.done


def test_reset_sets_soft_rst_and_waits_for_it_to_clear_on_the_clock() -> None:
    driver, bus, _ = driver_on([("W", 0x21, 0x04), ("R", 0x21, 1, b"\x04"), ("R", 0x21, 1, b"\x04"),
                                ("R", 0x21, 1, b"\x00")])
    driver.reset()
    assert bus.done and bus.at[1:] == pytest.approx([0.0, 0.001, 0.002])


def test_a_reset_that_never_clears_is_a_fault_within_its_deadline() -> None:
    driver, _, clock = driver_on([("W", 0x21, 0x04)] + [("R", 0x21, 1, b"\x04")] * 101)
    with pytest.raises(InstrumentError, match="SOFT_RST to clear after a soft reset: not reached within"):
        driver.reset()
    assert clock.now() == pytest.approx(RESET_TIMEOUT_S)


@pytest.mark.parametrize(("range_gauss", "odr_hz", "ctrl1", "ctrl2", "ctrl4"), [
    (4, 155, 0xE2, 0x00, 0x0C),      # TEMP_EN, OM 11 (UHP), FAST_ODR; FS 00; OMZ 11
    (12.0, 80, 0xFC, 0x40, 0x0C),    # UHP, DO 111 (80 Hz); FS 10; a procedure's float finds ±12
    (16, 1000, 0x82, 0x60, 0x00),    # low power, FAST_ODR; FS 11; OMZ 00
    (8, 300, 0xC2, 0x20, 0x08),      # high performance, FAST_ODR; FS 01; OMZ 10
])
def test_configure_writes_ctrl_reg1_2_4_5_keeps_the_mode_and_reads_all_five_back(range_gauss, odr_hz, ctrl1, ctrl2,
                                                                               ctrl4) -> None:
    driver, bus, _ = driver_on([("R", 0x22, 1, b"\x03"), ("W", 0x20, ctrl1), ("W", 0x21, ctrl2), ("W", 0x23, ctrl4),
                                ("W", 0x24, 0x40), ("R", 0x20, 5, bytes([ctrl1, ctrl2, 0x03, ctrl4, 0x40]))])
    driver.configure({"mag": range_gauss}, odr_hz)
    assert bus.done


def test_a_configuration_that_does_not_read_back_is_a_fault() -> None:
    driver, _, _ = driver_on([("R", 0x22, 1, b"\x03"), ("W", 0x20, 0xE2), ("W", 0x21, 0x00), ("W", 0x23, 0x0C),
                              ("W", 0x24, 0x40), ("R", 0x20, 5, b"\xe2\x20\x03\x0c\x40")])
    with pytest.raises(InstrumentError, match="CTRL_REG1…5 read back E2/20/03/0C/40, not E2/00/03/0C/40"):
        driver.configure({"mag": 4}, 155)


def test_configure_needs_its_channels_range() -> None:
    driver, _, _ = driver_on([])
    with pytest.raises(InstrumentError, match="no range given for its mag channel"):
        driver.configure({"accel": 2}, 155)


def test_read_settings_decodes_ctrl_reg1_and_2_and_refuses_what_is_no_rate() -> None:
    driver, bus, _ = driver_on([("R", 0x20, 2, b"\xe2\x40"), ("R", 0x20, 2, b"\x10\x00")])
    assert driver.read_settings() == ({"mag": 12}, 155)
    with pytest.raises(InstrumentError, match="CTRL_REG1/CTRL_REG2 read 10/00: no rate or range"):
        driver.read_settings()                                # the reset state: low power 10 Hz, not a table rate
    assert bus.done


def test_start_and_standby_write_the_mode_and_start_waits_out_the_turn_on() -> None:
    driver, bus, clock = driver_on([("W", 0x22, 0x00), ("W", 0x22, 0x03)])
    driver.start_measurement()
    assert clock.now() == pytest.approx(TURN_ON_S)
    driver.standby()
    assert bus.done


def test_temperature_is_one_burst_of_temp_out() -> None:
    driver, bus, _ = driver_on([("R", 0x2E, 2, (-120).to_bytes(2, "little", signed=True))])
    assert driver.read_temperature_c() == pytest.approx(25.0 - 15.0)
    assert bus.done


def test_acquire_polls_one_burst_per_sample_and_takes_only_new_ones() -> None:
    """At 155 Hz: a burst to clear STATUS, then each sample read once ZYXDA says it is new (a burst without it is
    polled again an eighth of a period later)."""
    configure = [("R", 0x22, 1, b"\x00"), ("W", 0x20, 0xE2), ("W", 0x21, 0x00), ("W", 0x23, 0x0C), ("W", 0x24, 0x40),
                 ("R", 0x20, 5, b"\xe2\x00\x00\x0c\x40")]
    bursts = [("R", 0x27, 9, sample(0xFF, (0, 0, 0), 0)),             # read first: clears STATUS
              ("R", 0x27, 9, sample(0x0F, (100, -200, 3000), 40)),
              ("R", 0x27, 9, sample(0x00, (100, -200, 3000), 40)),   # not new yet
              ("R", 0x27, 9, sample(0x0F, (101, -201, 3001), 48))]
    driver, bus, _ = driver_on(configure + bursts)
    driver.configure({"mag": 4}, 155)
    block = driver.acquire(2)
    assert bus.done
    np.testing.assert_array_equal(block.codes["mag"], [[100, -200, 3000], [101, -201, 3001]])
    assert block.temperature_c == (30.0, 31.0)
    assert block.t_end_s - block.t_start_s == pytest.approx(1 / 155)
    assert np.diff(bus.at[6:]) == pytest.approx([1 / 155, 1 / 155, 1 / 155 / 8])


def test_the_bridge_frames_a_burst_with_the_read_and_auto_increment_bits() -> None:
    """SPI: bit 7 read, bit 6 MS (address auto-increment) on a read of more than one register (DS9463 §5.2)."""
    spi = LIS3MDL.spi
    assert spi is not None
    assert spi.read_command(0x0F, 1) == 0x8F and spi.read_command(0x27, 9) == 0xE7
    assert spi.write_command(0x21) == 0x21
    assert spi.mode == 3                                       # SPC idles high, data captured on its rising edge


def test_spidev_opens_the_bus_in_the_parts_mode_and_frames_its_bursts(monkeypatch) -> None:
    """Over Linux spidev (a stand-in SpiDev: no kernel bus here): mode 3 and the MS bit on a burst."""
    import sys
    import types

    from accelcal_rig.instruments.adxl355_transport import SpidevBus

    class FakeSpiDev:
        def __init__(self) -> None:
            self.mode, self.max_speed_hz, self.sent = None, None, []

        def open(self, bus: int, chip_select: int) -> None:
            pass

        def xfer2(self, data: list[int]) -> list[int]:
            self.sent.append(list(data))
            return [0xFF] + [0x3D] * (len(data) - 1)

    monkeypatch.setitem(sys.modules, "spidev", types.SimpleNamespace(SpiDev=FakeSpiDev))
    bus = SpidevBus.open(0, 1, framing=LIS3MDL.spi)
    device = bus._device
    assert device.mode == 3
    assert bus.read(0x0F, 1) == b"\x3d" and bus.read(0x27, 9) == b"\x3d" * 9
    bus.write(0x24, 0x40)
    assert device.sent == [[0x8F, 0], [0xE7] + [0] * 9, [0x24, 0x40]]
