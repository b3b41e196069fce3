"""The shipped IMU procedures' acceptance limits are ones a healthy part passes and a part beyond its data sheet
fails (docs/procedures.md, "Limits a healthy part passes"): procedures/imu-fast.yaml as shipped, on two of
configs/sim-imu16.yaml's IMUs, the second made beyond the ICM-42688-P data sheet by the simulator's
`sensor_out_of_spec` fault."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from accelcal_rig.cli.commands import main
from accelcal_rig.fit.calibration import load_calibration
from tests.conftest import REPO

IMU_PROCEDURES = ("imu-fast.yaml", "imu-thermal.yaml", "paper-24pos-imu.yaml")


def acceptance(name: str) -> dict:
    return yaml.safe_load((REPO / "procedures" / name).read_text())["acceptance"]


def test_the_imu_procedures_share_their_limits() -> None:
    """One set of limits for one part: the accelerometer's in all three, the gyroscope's where it is calibrated."""
    fast, soak, paper = (acceptance(name) for name in IMU_PROCEDURES)
    assert fast == soak
    assert {k: v for k, v in fast.items() if k != "gyro"} == paper
    # Twice the data sheet's typical initial tolerances (DS-000347 Tables 1, 2): ±20 mg, ±0.5 °/s, ±0.5 %.
    assert fast["parameters"]["bias_mg"] == 40
    assert (fast["gyro"]["parameters"]["bias_dps"], fast["gyro"]["parameters"]["scale_error_ppm"]) == (1.0, 10000)


def campaign(tmp_path: Path, fault: dict) -> dict[str, dict[str, str]]:
    """imu-fast.yaml as shipped on IMU-F001 and IMU-F002 of the sixteen with the simulator's `fault`: each DUT's
    verdict per channel."""
    rig = yaml.safe_load((REPO / "configs" / "sim-imu16.yaml").read_text())
    rig["fixture"]["sensors"] = rig["fixture"]["sensors"][:2]
    rig["simulation"]["faults"] = fault
    (tmp_path / "rig.yaml").write_text(yaml.safe_dump(rig, sort_keys=False))
    procedure = yaml.safe_load((REPO / "procedures" / "imu-fast.yaml").read_text())
    (tmp_path / "imu-fast.yaml").write_text(yaml.safe_dump({**procedure, "rig": "rig.yaml"}, sort_keys=False))
    output = tmp_path / "c.h5"
    code = main(["run", str(tmp_path / "imu-fast.yaml"), "--dry-run", "-o", str(output), "-q", "--no-pdf",
                 "--no-publish", "--seed", "0"])
    assert code == 0
    calibration = load_calibration(output.with_suffix(".calibration.yaml"))
    return {serial: {name: str(channel.verdict) for name, channel in dut.channels.items()}
            for serial, dut in calibration.duts.items()}


@pytest.mark.parametrize(("fault", "failing"), [
    ({"sensor_out_of_spec_channel": "gyro", "sensor_out_of_spec_scale_pct": 2.0}, "gyro"),   # 4 × the ±0.5 %
    ({"sensor_out_of_spec_channel": "accel", "sensor_out_of_spec_bias": 0.06}, "accel"),      # 3 × the ±20 mg
])
def test_a_healthy_imu_passes_and_one_beyond_its_data_sheet_fails(tmp_path: Path, fault: dict, failing: str) -> None:
    verdicts = campaign(tmp_path, {"sensor_out_of_spec": "IMU-F002", **fault})
    assert verdicts["IMU-F001"] == {"accel": "PASS", "gyro": "PASS"}
    assert verdicts["IMU-F002"][failing] == "FAIL"
    assert {v for name, v in verdicts["IMU-F002"].items() if name != failing} == {"PASS"}
