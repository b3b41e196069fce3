"""The campaign-level fit on the paper's dry run: what the simulated data allow, and nothing invented."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.fit.campaign_fit import FitOptions, fit_and_save, fit_campaign
from accelcal_rig.store.content import measurements_sha256
from accelcal_rig.store.paths import journal_path
from accelcal_rig.store.read import load_campaign, read_hdf5_campaign


@pytest.fixture(scope="module")
def reports(paper_campaign: Path) -> dict[str, dict]:
    campaign = load_campaign(paper_campaign)
    """Per fit mode, each DUT's accelerometer figures (`rig fit --json`'s `channels.accel`)."""
    fitted = {mode: fit_campaign(campaign, FitOptions(mode=mode), {"campaign": "x"})[1] for mode in ("reference", "norm-only")}
    return {mode: {serial: dut["channels"]["accel"] for serial, dut in report.items()} for mode, report in fitted.items()}


@pytest.mark.parametrize("mode", ["reference", "norm-only"])
def test_fit_reaches_the_noise_floor_and_removes_the_drift(reports, mode: str) -> None:
    for serial, report in reports[mode].items():
        assert report["rmse_before_mg"] > 5.0                                  # a real error to remove
        assert report["rmse_after_mg"] < 1.5 * report["noise_floor_mg"], serial
        assert max(report["drift_after_mg"]) < 0.3                              # 0.3 mg: the product target (paper: 0.9–1.8 mg)
        assert min(report["drift_before_mg"]) > 5.0                             # the truth drifts 10–20 mg
        rows = report["rmse_by_setpoint"]
        assert [r["setpoint_c"] for r in rows] == list(range(-40, 61, 10))
        assert all(r["measurement_mg"] <= r["polynomial_mg"] + 0.01 for r in rows)


@pytest.mark.parametrize("mode", ["reference", "norm-only"])
def test_truth_errors_are_consistent_with_their_sigmas(reports, mode: str) -> None:
    for report in reports[mode].values():
        records = report["truth_error"]
        assert len(records) == 11 * (12 if mode == "reference" else 9)
        z = np.array([r["z"] for r in records])
        assert 0.7 < np.sqrt(np.mean(z**2)) < 1.3                                 # σ honest on average
        assert np.mean(np.abs(z) < 3) > 0.97                                       # Gaussian tails, not worse
        assert {"parameter", "setpoint_c", "error", "sigma", "z"} <= set(records[0])


def test_fitting_writes_only_the_calibration_and_never_the_campaign(paper_campaign: Path, tmp_path: Path) -> None:
    files = [paper_campaign, journal_path(paper_campaign)]
    before = [hashlib.sha256(f.read_bytes()).hexdigest() for f in files]
    calibration = tmp_path / "cal.yaml"
    fit_and_save(load_campaign(paper_campaign), paper_campaign, calibration, FitOptions(mode="reference"))
    first = calibration.read_text()
    fit_and_save(load_campaign(paper_campaign), paper_campaign, calibration, FitOptions(mode="norm-only", degree=2))
    assert [hashlib.sha256(f.read_bytes()).hexdigest() for f in files] == before
    assert calibration.read_text() != first and "mode: norm-only" in calibration.read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cal.yaml"]  # replaced whole, nothing left beside it


def test_the_journal_and_the_campaign_file_hold_the_same_measurements(paper_campaign: Path) -> None:
    from_journal, from_file = load_campaign(paper_campaign), read_hdf5_campaign(paper_campaign)
    assert from_journal.source == "journal" and from_file.source == "file"
    assert measurements_sha256(from_journal) == measurements_sha256(from_file)
    for serial in from_journal.serials:
        for name in ("temperature_c", "temperature_in_band"):
            np.testing.assert_array_equal(from_journal.dut_column(serial, name), from_file.dut_column(serial, name))
        for name in ("raw_codes", "mean", "stderr", "reference"):
            np.testing.assert_array_equal(from_journal.channel_column(serial, "accel", name),
                                          from_file.channel_column(serial, "accel", name))
