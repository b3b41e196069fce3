"""The data watchdog on every channel of a DUT's block: a stuck axis and a saturated code are transient
faults (a new block is taken), a channel the part has and the block lacks is a fault naming both."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from accelcal_rig.engine.acquisition import check_block
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.interfaces import SampleBlock
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.parts.icm42688 import ICM42688P
from accelcal_rig.parts.part import Part


@dataclass
class Dut:
    part: Part
    serial: str = "SN-1"
    endpoint: str = "memory"


def block(duration_s: float = 1.0, **codes: np.ndarray) -> SampleBlock:
    return SampleBlock(codes, 0.0, duration_s, (25.0, 25.0))


def noisy(n: int = 20) -> np.ndarray:
    return np.random.default_rng(0).integers(-50, 50, (n, 3)).astype(np.int32)


def test_a_block_with_every_channel_moving_within_range_passes() -> None:
    check_block(Dut(ICM42688P), block(accel=noisy(), gyro=noisy()), {"accel": 2, "gyro": 2000})  # type: ignore[arg-type]


def test_a_stuck_gyroscope_axis_is_named_with_its_channel() -> None:
    """At ±250 °/s and 200 Hz the gyroscope's noise (2.8 mdps/√Hz) is 3 codes: one frozen axis has stopped."""
    gyro = noisy()
    gyro[:, 1] = 7
    with pytest.raises(TransientInstrumentError, match="samples of gyro axis y reads the same code"):
        check_block(Dut(ICM42688P), block(0.1, accel=noisy(), gyro=gyro), {"accel": 2, "gyro": 250})  # type: ignore[arg-type]


def test_a_channel_coarser_than_its_noise_is_stuck_only_when_every_axis_is() -> None:
    """At ±2000 °/s (0.061 °/s a code) the same noise is 0.3 code: a still axis may hold one code a whole
    block; every axis frozen at once is a sensor that stopped."""
    gyro = noisy()
    gyro[:, 1] = 7
    check_block(Dut(ICM42688P), block(0.1, accel=noisy(), gyro=gyro), {"accel": 2, "gyro": 2000})  # type: ignore[arg-type]
    gyro[:, :] = 7
    with pytest.raises(TransientInstrumentError, match="samples of gyro axis x,y,z reads the same code"):
        check_block(Dut(ICM42688P), block(0.1, accel=noisy(), gyro=gyro), {"accel": 2, "gyro": 2000})  # type: ignore[arg-type]


def test_a_saturated_code_names_the_range_in_the_channels_unit() -> None:
    accel = noisy()
    accel[3, 0] = ADXL355.channel("accel").code_max
    with pytest.raises(TransientInstrumentError, match=r"saturated at ±2 g"):
        check_block(Dut(ADXL355), block(accel=accel), {"accel": 2})  # type: ignore[arg-type]


def test_a_channel_the_block_lacks_is_a_fault_naming_both_sides() -> None:
    with pytest.raises(InstrumentError, match="holds no gyro codes .*reads accel; its part has accel, gyro"):
        check_block(Dut(ICM42688P), block(accel=noisy()), {"accel": 2, "gyro": 2000})  # type: ignore[arg-type]
