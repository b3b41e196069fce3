"""A procedure names each channel's range; the cross-check holds every channel of every DUT's part to it."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from accelcal_rig.config.procedure import Acquisition
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import ConfigError
from tests.conftest import TINY_PROCEDURE

IMU_PROCEDURE = TINY_PROCEDURE.replace("odr_hz: 125", "odr_hz: 100")


def with_imus(workdir: Path, count: int = 2) -> None:
    """The copied sim rig with ICM-42688-P DUTs on its first sensors (and only those)."""
    path = workdir / "sim.yaml"
    config = yaml.safe_load(path.read_text())
    config["fixture"]["sensors"] = [dict(s, part="icm42688p") for s in config["fixture"]["sensors"][:count]]
    path.write_text(yaml.safe_dump(config, sort_keys=False))


def test_ranges_hold_the_gyro_only_when_given() -> None:
    assert Acquisition().ranges == {"accel": 2}
    assert Acquisition(range_dps=2000).ranges == {"accel": 2, "gyro": 2000}
    assert Acquisition(range_dps=15.625).ranges["gyro"] == 15.625
    assert Acquisition(ranges={"accel": 4, "gyro": 250}).ranges == {"accel": 4, "gyro": 250}
    assert Acquisition(ranges={"mag": 4}).ranges == {"accel": 2, "mag": 4}     # the accelerometer's 2 g unless given
    with pytest.raises(ValueError, match="range_g"):
        Acquisition(range_g=2, ranges={"accel": 4})


def test_an_adxl355_procedure_is_unchanged_by_a_range_dps(write) -> None:
    prepare(write("tiny.yaml", TINY_PROCEDURE))  # no range_dps: the ADXL355 rig needs none
    prepare(write("tiny.yaml", TINY_PROCEDURE.replace("settle_s: 1", "settle_s: 1, range_dps: 2000")))


def test_an_imu_rig_needs_range_dps_named_in_one_line(write, workdir: Path) -> None:
    with_imus(workdir)
    path = write("tiny.yaml", IMU_PROCEDURE)
    with pytest.raises(ConfigError) as raised:
        prepare(path)
    message = str(raised.value)
    assert "\n" not in message
    assert message.startswith(f"{path}:6: acquisition.ranges.gyro: not set: sensor ADX355-A001 of ")
    assert message.endswith("is an ICM-42688-P, whose gyro channel needs its ± full scale in dps")


@pytest.mark.parametrize(("acquisition", "expected"), [
    ("range_dps: 3000", r"tiny.yaml:6: acquisition.range_dps: ±3000 dps is not a range of the ICM-42688-P "
                        r"\(±15.625/31.25/62.5/125/250/500/1000/2000 dps\): sensor ADX355-A001"),
    ("range_dps: 2000, range_g: 3", r"acquisition.range_g: ±3 g is not a range of the ICM-42688-P \(±2/4/8/16 g\)"),
    ("range_dps: 2000, odr_hz: 40000", r"acquisition.odr_hz: 40000 Hz is faster than every ICM-42688-P output data "
                                       r"rate"),
])
def test_every_channel_of_an_imu_is_checked(write, workdir: Path, acquisition: str, expected: str) -> None:
    with_imus(workdir)
    text = IMU_PROCEDURE
    for item in acquisition.split(", "):
        key = item.split(":")[0]
        if key in text:
            text = text.replace(f"{key}: {'2' if key == 'range_g' else '100'}", item, 1)
        else:
            text = text.replace("settle_s: 1", f"settle_s: 1, {item}")
    with pytest.raises(ConfigError, match=expected):
        prepare(write("tiny.yaml", text))


def test_an_imu_rig_with_range_dps_prepares(write, workdir: Path) -> None:
    with_imus(workdir)
    prepare(write("tiny.yaml", IMU_PROCEDURE.replace("settle_s: 1", "settle_s: 1, range_dps: 15.625")))
