"""The simulated LIS3MDL: its register model against the data sheet's behaviour (reset values, SOFT_RST, STATUS's
ZYXDA and ZYXOR), its hidden truth in the site's field, and the driver through a version 3 serial bridge on a
pseudo-terminal."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.fit.sfem import distort
from accelcal_rig.instruments import lis3mdl as regs
from accelcal_rig.instruments.adxl355_transport import SerialBridge
from accelcal_rig.instruments.lis3mdl_driver import Lis3mdl
from accelcal_rig.parts.lis3mdl import LIS3MDL
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.lis3mdl_bridge_server import REGISTER_MAP
from accelcal_rig.sim.lis3mdl_registers import SimulatedLis3mdl
from accelcal_rig.sim.register_bridge_server import SimulatedRegisterBridge
from accelcal_rig.sim.truth import mag_truth_for_serial
from tests.conftest import REPO

MIXED_RIG = REPO / "configs" / "sim-mixed.yaml"
MAG_INDEX = 4  # the fixture's first LIS3MDL, after four ADXL355s


def mixed_lab(seed: int = 5) -> tuple[VirtualLab, VirtualClock]:
    clock = VirtualClock()
    return VirtualLab(RigConfig.model_validate(yaml.safe_load(MIXED_RIG.read_text())), clock, seed), clock


def test_registers_identity_reset_values_and_soft_reset() -> None:
    lab, _ = mixed_lab()
    device = SimulatedLis3mdl(lab, MAG_INDEX)
    assert device.read(regs.REG_WHO_AM_I, 1) == b"\x3d"
    assert device.read(regs.REG_CTRL1, 5) == bytes([0x10, 0x00, 0x03, 0x00, 0x00])   # power-down, ±4 gauss
    assert device.read(regs.REG_INT_CFG, 1) == b"\xe8"
    device.write(regs.REG_WHO_AM_I, 0)                                   # read-only: ignored
    device.write(0x00, 0x55)                                            # reserved: ignored
    assert device.read(regs.REG_WHO_AM_I, 1) == b"\x3d" and device.read(0x00, 1) == b"\x00"
    device.write(regs.REG_CTRL1, 0xE2)
    device.write(regs.REG_CTRL2, 0x60)
    assert device.read(regs.REG_CTRL1, 2) == b"\xe2\x60"
    device.write(regs.REG_CTRL2, regs.CTRL2_SOFT_RST | 0x60)           # every register back to its reset value
    assert device.read(regs.REG_CTRL1, 3) == bytes([0x10, 0x00, 0x03])  # and SOFT_RST clear again


def test_data_registers_hold_a_new_sample_each_period_with_zyxda_and_zyxor() -> None:
    lab, clock = mixed_lab()
    device = SimulatedLis3mdl(lab, MAG_INDEX)
    device.write(regs.REG_CTRL1, 0xE2)                                  # UHP, 155 Hz
    assert device.read(regs.REG_STATUS, 1) == b"\x00"                   # power-down: nothing converts
    device.write(regs.REG_CTRL3, regs.CTRL3_CONTINUOUS)
    clock.sleep(1.01 / 155)
    first = device.read(regs.REG_STATUS, regs.SAMPLE_BYTES)
    assert first[0] == 0x0F                                              # ZYXDA and each axis's
    again = device.read(regs.REG_STATUS, regs.SAMPLE_BYTES)
    assert again[0] == 0 and again[1:7] == first[1:7]                   # read: the same sample, not new
    clock.sleep(3 / 155)                                                 # two went by unread
    assert device.read(regs.REG_STATUS, 1)[0] == 0xFF                    # ZYXOR: overrun
    device.read(regs.REG_OUT_X_L, 6)
    assert device.read(regs.REG_STATUS, 1)[0] == 0


def test_the_driver_through_a_version_3_bridge_reads_the_site_field_through_the_hidden_truth() -> None:
    lab, clock = mixed_lab(seed=7)
    dut = lab.duts[MAG_INDEX]
    server = SimulatedRegisterBridge(lab, MAG_INDEX, SimulatedLis3mdl(lab, MAG_INDEX), REGISTER_MAP).start()
    bridge = SerialBridge.open(server.path)
    driver = Lis3mdl(bridge, dut.serial, clock, LIS3MDL)
    try:
        assert bridge.part_name == "lis3mdl" and bridge.capture_capacity_samples == 0
        assert LIS3MDL.wrong_identity(driver.identify().registers) is None
        driver.reset()
        driver.configure({"mag": 4}, 155)
        driver.start_measurement()
        assert driver.read_settings() == ({"mag": 4}, 155)
        block = clock.run_concurrently([lambda: driver.acquire(400)])[0]
        with pytest.raises(InstrumentError, match="refused: read-only register 0x0F"):
            bridge.write(regs.REG_WHO_AM_I, 0)
    finally:
        driver.close()
        server.stop()
    field = block.codes["mag"]
    assert field.shape == (400, 3) and len({tuple(row) for row in field}) > 300   # new samples, not re-reads
    assert block.t_end_s - block.t_start_s == pytest.approx(399 / 155)
    # The site's field (48 818 nT) in the DUT's frame at the table's angles, through its hard and soft iron,
    # with the data sheet's 3.2 mgauss RMS noise at 155 Hz.
    temperature = lab.dut_true_c(MAG_INDEX)
    world = lab.field_world_gauss
    assert np.linalg.norm(world) == pytest.approx(0.488177, rel=1e-3)
    expected = distort(dut.fixture_to_dut @ lab.kinematics.world_in_fixture(lab.motion.position_deg(clock.now()),
                                                                            world),
                       mag_truth_for_serial(dut.serial).parameters_at(temperature))
    assert field.mean(axis=0) / 6842 == pytest.approx(expected, abs=5e-4)
    assert field.std(axis=0, ddof=1).mean() / 6842 == pytest.approx(3.2e-3, rel=0.2)
    assert block.temperature_c[0] == pytest.approx(temperature, abs=0.2)
    hard_iron = mag_truth_for_serial(dut.serial).parameters_at(25.0)[:3]
    assert np.all(np.abs(hard_iron) < 1.0) and np.any(np.abs(hard_iron) > 0.05)  # the data sheet's ±1 gauss
