"""The campaign file's layout after a tiny dry run, and the documented way of reading it."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

from accelcal_rig.fit.sfem import distort
from accelcal_rig.store.read import campaign_status
from tests.conftest import REPO


def test_layout_shapes_and_units(campaign: Path) -> None:
    with h5py.File(campaign, "r") as f:
        assert f.attrs["format"] == "accelcal-rig campaign" and f.attrs["state"] == "done"
        assert f["plan/step_key"].shape == (7,)
        assert f["poses/commanded_angles_deg"].shape == (6, 3)
        assert f["poses/chamber_temperature_c"].attrs["unit"] == "degC"
        assert "six-position" in f["config/procedure_yaml"][()].decode()
        assert set(f["duts"]) == {"ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"}
        for serial, dut in f["duts"].items():
            assert dut["accel/raw_codes"].shape == (6, 20, 3) and dut["accel/raw_codes"].dtype == np.int32
            assert dut["accel/mean"].attrs["unit"] == "g"
            np.testing.assert_allclose(dut["accel/mean"][:], dut["accel/raw_codes"][:].mean(axis=1) * dut["accel"].attrs["lsb"])
            settled = f["soaks/T30/settled_dut_c"][list(f["duts"]).index(serial)]
            drift = np.abs(dut["temperature_c"][:] - settled).max(axis=1)
            np.testing.assert_array_equal(dut["temperature_in_band"][:], drift <= 0.3)
            truth = f["simulation_truth"][serial]
            assert truth["parameters"].shape == (6, 12)
        assert f["soaks/T30"].attrs["outcome"] == "stable"
        assert f["instruments/chamber"].attrs["endpoint"]


def test_means_agree_with_the_simulation_truth_and_the_reference(campaign: Path) -> None:
    with h5py.File(campaign, "r") as f:
        for serial, dut in f["duts"].items():
            truth = f["simulation_truth"][serial]
            expected = distort(truth["gravity_g"][:], truth["parameters"][:])
            # 20 samples at 0.2 mg each: means within 5 standard errors of the truth
            assert np.all(np.abs(dut["accel/mean"][:] - expected) < 5 * dut["accel/stderr"][:] + 1e-6)
            # The reference from commanded angles is the truth but for turntable accuracy (3″ ≈ 15 µg)
            np.testing.assert_allclose(dut["accel/reference"][:], truth["gravity_g"][:], atol=3e-5)


def test_status_reports_progress(campaign: Path) -> None:
    status = campaign_status(campaign)
    assert status["state"] == "done"
    assert (status["poses_done"], status["poses_total"], status["samples_per_pose"]) == (6, 6, 20)
    assert status["setpoints_c"] == [30.0]
    assert status["next_step"] is None and status["finished"]


def test_the_documented_reading_snippet_runs(campaign: Path) -> None:
    doc = (REPO / "docs" / "hdf5-layout.md").read_text()
    snippet = re.search(r"```python\n(.*?)```", doc, re.S).group(1).replace("campaign.h5", str(campaign))
    result = subprocess.run([sys.executable, "-c", snippet], capture_output=True, text=True, check=True)
    assert result.stdout.count("(6, 3)") == 4


def test_every_dataset_carries_a_checksum_and_the_file_names_its_journal(campaign: Path) -> None:
    from accelcal_rig.store.paths import journal_path
    from accelcal_rig.store.read import load_campaign

    with h5py.File(campaign, "r") as f:
        datasets = []
        f.visititems(lambda name, node: datasets.append(node) if isinstance(node, h5py.Dataset) and node.size > 1 else None)
        assert datasets and all(d.fletcher32 for d in datasets)
        assert f.attrs["format_version"] == 3 and "fit" not in f
        assert f.attrs["journal_bytes"] == journal_path(campaign).stat().st_size
        assert f.attrs["campaign_id"] == load_campaign(campaign).header.campaign_id


def test_the_file_records_each_instruments_driver_and_endpoint(campaign: Path) -> None:
    with h5py.File(campaign, "r") as f:
        chamber = dict(f["instruments/chamber"].attrs)
        turntable = dict(f["instruments/turntable"].attrs)
        assert chamber["driver"] == "ModbusChamber" and chamber["endpoint"].startswith("modbus-tcp 127.0.0.1:")
        assert turntable["driver"] == "SerialTurntable" and turntable["endpoint"].startswith("serial /dev/pts/")
        for dut in f["duts"].values():
            assert dut.attrs["driver"] == "Adxl355" and dut.attrs["endpoint"].startswith("serial /dev/pts/")


def test_each_soak_keeps_the_ramp_before_it_in_the_journal_and_the_file(campaign: Path) -> None:
    """The chamber air polled from the set point's write until it was reached: what `rig characterise`
    fits the chamber's rates and lag to. The journal and the file hold the same polls."""
    from accelcal_rig.store.hdf5_file import read_campaign_file
    from accelcal_rig.store.read import load_campaign

    from_journal = load_campaign(campaign)
    with h5py.File(campaign, "r") as f:
        from_file = read_campaign_file(f)
        ramp_t_s, ramp_c = f["soaks/T30/ramp_t_s"][:], f["soaks/T30/ramp_chamber_c"][:]
    (soak,) = from_journal.soaks
    assert len(soak.ramp_t_s) > 2 and np.all(np.diff(soak.ramp_t_s) >= 0)
    assert soak.ramp_t_s[-1] <= soak.t_reached_s + 1e-9
    assert abs(soak.ramp_chamber_c[0] - 23.0) < 1.0 and abs(soak.ramp_chamber_c[-1] - 30.0) <= 1.0  # room → 30 °C, within tolerance
    np.testing.assert_array_equal(from_file.soaks[0].ramp_t_s, soak.ramp_t_s)
    np.testing.assert_array_equal(ramp_c, soak.ramp_chamber_c)
    np.testing.assert_array_equal(ramp_t_s, soak.ramp_t_s)
