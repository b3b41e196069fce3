"""A dry run of ICM-42688-P DUTs end to end: the simulated part chosen by the rig config's `part:`, through
its driver and a version 3 bridge, both channels stored per DUT, readable with bare h5py."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.sim.truth import gyro_truth_for_serial
from tests.conftest import TINY_PROCEDURE


def test_a_dry_run_of_imus_stores_accel_and_gyro_codes(write, workdir: Path) -> None:
    path = workdir / "sim.yaml"
    config = yaml.safe_load(path.read_text())
    config["fixture"]["sensors"] = [dict(s, part="icm42688p") for s in config["fixture"]["sensors"][:2]]
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    procedure = write("tiny.yaml", TINY_PROCEDURE.replace("odr_hz: 125", "odr_hz: 100, range_dps: 2000"))
    output = workdir / "run.h5"
    run_campaign(prepare(procedure), output, dry_run=True, seed=3, overwrite=False)
    with h5py.File(output, "r") as campaign:
        for serial in ("ADX355-A001", "ADX355-A002"):
            dut = campaign[f"duts/{serial}"]
            assert dut.attrs["part"] == "icm42688p"
            accel, gyro = dut["accel/raw_codes"][()], dut["gyro/raw_codes"][()]
            assert accel.shape == gyro.shape == (6, 20, 3) and gyro.dtype == np.int32
            # Six positions: 1 g along ±x, ±y, ±z at 16 384 LSB/g on ±2 g.
            norm_g = np.linalg.norm(accel.mean(axis=1), axis=1) / 16384
            assert np.all(np.abs(norm_g - 1.0) < 0.05)
            # The gyroscope at rest reads its hidden bias near 30 °C whatever the pose, at 16.4 LSB/(°/s).
            bias_dps = gyro_truth_for_serial(serial).parameters_at(30.0)[:3]
            assert gyro.mean(axis=(0, 1)) / 16.4 == pytest.approx(bias_dps, abs=0.02)
            np.testing.assert_array_equal(dut["gyro/reference"][()], np.zeros((6, 3)))
