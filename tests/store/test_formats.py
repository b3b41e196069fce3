"""Campaigns written before parts declared channels (format 2, tests/data/format2: written by an earlier
accelcal-rig) read as one acceleration channel from their file and from their journal, and `rig repair`
rewrites them as format 3, value for value."""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from accelcal_rig.store.content import measurements_sha256
from accelcal_rig.store.paths import journal_path
from accelcal_rig.store.read import load_campaign, read_hdf5_campaign
from accelcal_rig.store.repair import repair_campaign
from tests.conftest import REPO

FORMAT_2 = REPO / "tests" / "data" / "format2" / "format2.h5"
_OLD_NAMES = {"raw_codes": "raw_codes", "mean": "mean_g", "stderr": "stderr_g", "reference": "gravity_reference_g"}


@pytest.fixture
def format2(tmp_path: Path) -> Path:
    shutil.copy(FORMAT_2, tmp_path / "format2.h5")
    shutil.copy(journal_path(FORMAT_2), journal_path(tmp_path / "format2.h5"))
    return tmp_path / "format2.h5"


def _datasets_as_written(path: Path) -> tuple[dict[str, dict[str, np.ndarray]], str]:
    with h5py.File(path, "r") as f:
        assert f.attrs["format_version"] == 2
        return ({serial: {name: dut[old][:] for name, old in _OLD_NAMES.items()} for serial, dut in f["duts"].items()},
                str(f.attrs["measurements_sha256"]))


@pytest.mark.parametrize("source", ["journal", "file"])
def test_a_format_2_campaign_reads_as_one_acceleration_channel(format2: Path, source: str) -> None:
    written, digest = _datasets_as_written(format2)
    campaign = load_campaign(format2) if source == "journal" else read_hdf5_campaign(format2)
    assert campaign.source == source and not campaign.integrity_problems()
    for serial, old in written.items():
        (channel,) = campaign.header.dut_channels(serial)
        assert (channel.name, channel.unit, channel.axes) == ("accel", "g", ("x", "y", "z"))
        assert channel.lsb == campaign.header.duts[campaign.serials.index(serial)]["lsb_g"]
        for name, values in old.items():
            np.testing.assert_array_equal(campaign.channel_column(serial, "accel", name), values)
    assert measurements_sha256(campaign) == digest  # the digest format 2 wrote still holds


def test_rig_repair_rewrites_a_format_2_campaign_as_format_3_value_for_value(format2: Path) -> None:
    written, digest = _datasets_as_written(format2)
    repair_campaign(format2)
    with h5py.File(format2, "r") as f:
        assert f.attrs["format_version"] == 3 and f.attrs["measurements_sha256"] == digest
        for serial, old in written.items():
            accel = f[f"duts/{serial}/accel"]
            assert accel.attrs["unit"] == "g" and list(accel.attrs["axes"]) == ["x", "y", "z"]
            assert "raw_codes" not in f[f"duts/{serial}"]
            for name, values in old.items():
                np.testing.assert_array_equal(accel[name][:], values)
    assert not load_campaign(format2).integrity_problems()


def test_a_record_at_a_finer_range_keeps_it_in_the_journal_and_the_hdf5_file(imu_dry_run, tmp_path: Path) -> None:
    """The small IMU campaign takes its gyroscope's records at rest and at low rates at ±250 °/s: the journal
    and the HDF5 file both hold each record's range (the file only where some record differs), read the same,
    and the measurements' digest covers them; a campaign at one range keeps its old digest (the quick dry run's
    files carry none)."""
    from tests.report.imu_campaign import copied

    campaign_path, _ = copied(imu_dry_run, tmp_path)
    from_journal, from_file = load_campaign(campaign_path), read_hdf5_campaign(campaign_path)
    serial = from_journal.serials[0]
    ranges = from_journal.channel_ranges(serial, "gyro")
    assert set(ranges.tolist()) == {250.0, 2000.0}
    assert np.array_equal(ranges, from_file.channel_ranges(serial, "gyro"))
    assert set(from_journal.channel_ranges(serial, "accel").tolist()) == {2.0}
    with h5py.File(campaign_path) as file:
        assert f"duts/{serial}/gyro/range" in file and f"duts/{serial}/accel/range" not in file
    assert measurements_sha256(from_journal) == measurements_sha256(from_file)
    # The samples in °/s follow each record's own code size: 8 × finer at ±250 than at ±2000.
    values = from_journal.channel_values(serial, "gyro")
    codes = from_journal.channel_column(serial, "gyro", "raw_codes")
    fine = ranges == 250.0
    lsb = from_journal.channel_info(serial, "gyro").lsb
    assert np.allclose(values[fine], codes[fine] * lsb / 8) and np.allclose(values[~fine], codes[~fine] * lsb)
    # Another range for the same codes is another measurement.
    changed = from_journal.poses[0].duts[0].channels["gyro"]
    from dataclasses import replace
    from_journal.poses[0].duts[0].channels["gyro"] = replace(changed, range=None if changed.range else 250.0)
    from_journal._columns.clear()
    assert measurements_sha256(from_journal) != measurements_sha256(from_file)


def test_a_record_range_that_is_no_range_is_one_line_naming_the_dataset(imu_dry_run, tmp_path: Path) -> None:
    """A damaged or tampered `range` dataset (a negative or infinite ± full scale) is damage said in one line
    naming the file and the dataset, never codes scaled by it."""
    from accelcal_rig.errors import ConfigError
    from tests.report.imu_campaign import copied

    campaign_path, _ = copied(imu_dry_run, tmp_path)
    serial = load_campaign(campaign_path).serials[0]
    for bad in (-250.0, np.inf):
        with h5py.File(campaign_path, "r+") as file:
            file[f"duts/{serial}/gyro/range"][0] = bad
        with pytest.raises(ConfigError) as refused:
            read_hdf5_campaign(campaign_path)
        message = str(refused.value)
        assert "\n" not in message and str(campaign_path) in message
        assert f"duts/{serial}/gyro/range row 1: {bad}, not a ± full scale" in message
