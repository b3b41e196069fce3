"""The campaign-level fit on the paper's dry run: what the simulated data allow, and nothing invented."""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from accelcal_rig.fit.campaign_fit import FitOptions, fit_campaign
from accelcal_rig.store.read import measurements_sha256


@pytest.fixture(scope="module")
def reports(paper_campaign: Path, tmp_path_factory) -> dict[str, dict]:
    copy = tmp_path_factory.mktemp("fit") / "campaign.h5"
    shutil.copy(paper_campaign, copy)
    out = {}
    with h5py.File(copy, "a") as file:
        for mode in ("reference", "norm-only"):
            out[mode] = fit_campaign(file, FitOptions(mode=mode), {"campaign": "x"})[1]
    return out


@pytest.mark.parametrize("mode", ["reference", "norm-only"])
def test_fit_reaches_the_noise_floor_and_removes_the_drift(reports, mode: str) -> None:
    for serial, report in reports[mode].items():
        assert report["rmse_before_mg"] > 5.0                                  # a real error to remove
        assert report["rmse_after_mg"] < 1.5 * report["noise_floor_mg"], serial
        assert max(report["drift_after_mg"]) < 0.3                              # target of DESIGN §8
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


def test_refitting_replaces_the_fit_group_and_leaves_measurements_alone(paper_campaign: Path, tmp_path: Path) -> None:
    copy = tmp_path / "campaign.h5"
    shutil.copy(paper_campaign, copy)
    with h5py.File(copy, "a") as file:
        digest = measurements_sha256(file)
        raw_before = file["duts/ADX355-A001/raw_codes"][:]
        fit_campaign(file, FitOptions(mode="reference"), {"campaign": "x"})
        fit_campaign(file, FitOptions(mode="norm-only", degree=2), {"campaign": "x"})
        assert file["fit"].attrs["mode"] == "norm-only"
        assert file["fit"].attrs["polynomial_degree"] == 2
        assert sorted(file["fit"]) == sorted(file["duts"])
        assert file["fit/ADX355-A001/polynomial_coefficients"].shape == (12, 3)
        assert measurements_sha256(file) == digest
        np.testing.assert_array_equal(file["duts/ADX355-A001/raw_codes"][:], raw_before)
