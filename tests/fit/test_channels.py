"""A DUT with a channel no channel model calibrates yet (an IMU's gyroscope): the campaign stores it in
every format path (journal, campaign file), the fit calibrates the accelerometer and names the other
channel with why, and the exports, the certificate and the report say plainly what they leave out."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.export.flight_stack import StackOptions
from accelcal_rig.export.formats import export
from accelcal_rig.fit.campaign_fit import FitOptions, fit_and_save, summary_line
from accelcal_rig.report.certificate import write_certificates
from accelcal_rig.report.html_report import write_report
from accelcal_rig.store.hdf5_file import campaign_image
from accelcal_rig.store.paths import journal_path
from accelcal_rig.store.read import load_campaign, read_hdf5_campaign
from accelcal_rig.store.records import ChannelInfo, ChannelPoseRecord
from accelcal_rig.store.repair import journal_bytes_of
from tests.conftest import REPO

GYRO = ChannelInfo("gyro", "angular rate", "dps", ("x", "y", "z"), 2000.0, 1 / 16.4)


@pytest.fixture(scope="module")
def with_gyro(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The quick campaign as if every DUT had also measured angular rate: codes of a resting gyroscope."""
    folder = tmp_path_factory.mktemp("gyro")
    measured = folder / "measured.h5"
    run_campaign(prepare(REPO / "procedures" / "quick-6pos.yaml"), measured, dry_run=True, seed=0, overwrite=False)
    campaign = load_campaign(measured)
    rng = np.random.default_rng(1)
    header = dataclasses.replace(campaign.header, channels={
        serial: (*campaign.header.dut_channels(serial), GYRO) for serial in campaign.serials})
    poses = []
    for pose in campaign.poses:
        duts = []
        for dut in pose.duts:
            codes = rng.integers(-3, 4, size=(campaign.samples_per_pose, 3)).astype(np.int32) + np.array([5, -2, 1], np.int32)
            gyro = ChannelPoseRecord(codes, codes.mean(axis=0) * GYRO.lsb, codes.std(axis=0, ddof=1) * GYRO.lsb, np.zeros(3))
            duts.append(dataclasses.replace(dut, channels={**dut.channels, "gyro": gyro}))
        poses.append(dataclasses.replace(pose, duts=duts))
    campaign = dataclasses.replace(campaign, header=header, poses=poses)
    output = folder / "imu.h5"
    journal = journal_bytes_of(campaign)
    journal_path(output).write_bytes(journal)
    output.write_bytes(campaign_image(campaign, len(journal)))
    return output


def test_every_channel_is_stored_and_read_back_from_the_journal_and_the_file(with_gyro: Path) -> None:
    from_journal, from_file = load_campaign(with_gyro), read_hdf5_campaign(with_gyro)
    for campaign in (from_journal, from_file):
        assert [c.name for c in campaign.header.dut_channels("ADX355-A001")] == ["accel", "gyro"]
        assert not campaign.integrity_problems()
    for serial in from_journal.serials:
        for name in ("raw_codes", "mean", "stderr", "reference"):
            np.testing.assert_array_equal(from_journal.channel_column(serial, "gyro", name),
                                          from_file.channel_column(serial, "gyro", name))
    with h5py.File(with_gyro, "r") as f:  # bare h5py: a group per channel, with its unit
        gyro = f["duts/ADX355-A001/gyro"]
        assert gyro.attrs["unit"] == "dps" and gyro.attrs["quantity"] == "angular rate"
        assert gyro["raw_codes"].shape == (len(f["poses/step_key"]), f.attrs["samples_per_pose"], 3) and gyro["mean"].attrs["unit"] == "dps"


def test_the_fit_calibrates_the_accelerometer_and_names_the_gyroscope_with_why(with_gyro: Path, tmp_path: Path) -> None:
    calibration, report = fit_and_save(load_campaign(with_gyro), with_gyro, tmp_path / "cal.yaml", FitOptions())
    for serial, dut in calibration.duts.items():
        assert set(dut.channels) == {"accel"} and set(dut.not_calibrated) == {"gyro"}
        assert "angular rate" in dut.not_calibrated["gyro"] and "no rate steps" in dut.not_calibrated["gyro"]
        assert report[serial]["not_calibrated"] == dut.not_calibrated
    assert summary_line(report, tmp_path / "cal.yaml").endswith("not calibrated (measured and stored): gyro")
    with pytest.raises(KeyError, match="no calibration of its gyro channel"):
        calibration.channel("ADX355-A001", "gyro")


@pytest.mark.parametrize("format_name", ["json", "csv", "c-header", "px4-params"])
def test_every_export_says_which_channel_it_leaves_out(with_gyro: Path, tmp_path: Path, format_name: str) -> None:
    calibration, _ = fit_and_save(load_campaign(with_gyro), with_gyro, tmp_path / "cal.yaml", FitOptions())
    options = StackOptions(tmp_path / "cal.yaml", serial="ADX355-A001" if format_name == "px4-params" else None)
    exported = export(calibration, format_name, options)
    left = [note for note in exported.notes if "gyro channel is not in this export" in note]
    assert len(left) == (1 if format_name == "px4-params" else 4)
    if format_name == "json":
        assert json.loads(exported.text)  # still the accelerometer's calibration, whole


def test_the_certificate_and_the_report_say_the_gyroscope_is_not_calibrated(with_gyro: Path, tmp_path: Path) -> None:
    calibration = tmp_path / "cal.yaml"
    fit_and_save(load_campaign(with_gyro), with_gyro, calibration, FitOptions())
    written, _ = write_certificates(with_gyro, calibration, tmp_path / "certificates", pdf=False)
    page = written[0].html.read_text()
    assert "NOT CALIBRATED: its gyro channel (angular rate in dps" in page and "MEMS accelerometer channel" in page
    report = write_report(with_gyro, tmp_path / "report").read_text()
    assert "<b>Not calibrated:</b> the gyro channel of 4 DUTs" in report
