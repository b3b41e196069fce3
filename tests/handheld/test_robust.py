"""The real session's intervals scatter more than their standard errors say: a scatter floor brings χ²_red
to 1, and then no interval counts for more because it lasted longer."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.fit.lm import fit_sfem
from accelcal_rig.fit.robust import fit_norm_only_with_floor
from accelcal_rig.handheld.calibrate import fit_recording
from accelcal_rig.handheld.recording import read_csv_recording
from accelcal_rig.handheld.static_intervals import DetectorSettings, detect_static_intervals
from tests.handheld.test_real_recording import LAYOUT, SESSION

#: A looser detector takes two short stretches of the rotations as still too: eight intervals, two to spare.
LOOSE = DetectorSettings(threshold_factor=100.0)


@pytest.fixture(scope="module")
def loose():
    recording = read_csv_recording(SESSION, LAYOUT)
    return recording, detect_static_intervals(recording.t_s, recording.accel_g, None, LOOSE, "session")


def test_the_floor_brings_chi2_to_1_and_is_reported(loose) -> None:
    recording, detection = loose
    result = fit_recording(recording, detection, "bias-scale", "imucal")
    report = result.report
    assert len(detection.intervals) == 8 and report["chi2_reduced_before"] > 3
    assert report["chi2_reduced"] == pytest.approx(1.0, abs=1e-3) and report["scatter_floor_mg"] > 0.1
    assert any("scatter floor" in w for w in report["warnings"])


def test_one_longer_interval_no_longer_drags_the_calibration(loose) -> None:
    _, detection = loose
    mean = np.array([i.mean_g for i in detection.intervals])
    stderr = np.array([i.stderr_g for i in detection.intervals])
    plain, floored = [], []
    for k in range(len(mean)):
        longer = stderr.copy()
        longer[k] /= np.sqrt(10)  # as if that interval had lasted ten times as long
        plain.append(fit_sfem(mean, longer, None, "norm-only", "bias-scale").parameters
                     - fit_sfem(mean, stderr, None, "norm-only", "bias-scale").parameters)
        floored.append(fit_norm_only_with_floor(mean, longer, "bias-scale").fit.parameters
                       - fit_norm_only_with_floor(mean, stderr, "bias-scale").fit.parameters)
    worst_plain, worst_floored = np.abs(plain)[:, :3].max(), np.abs(floored)[:, :3].max()
    assert worst_plain > 1e-4 and worst_floored < 0.4 * worst_plain  # bias, g: 0.17 mg without, 0.05 mg with


def test_standard_errors_that_explain_the_scatter_are_believed() -> None:
    rng = np.random.default_rng(4)
    gravity = rng.normal(size=(30, 3))
    gravity /= np.linalg.norm(gravity, axis=1, keepdims=True)
    stderr = np.full((30, 3), 2e-5)
    noisy = gravity * np.array([1.001, 0.999, 1.0]) + 0.002 + rng.normal(0, 0.5e-5, gravity.shape)  # less than stated
    result = fit_norm_only_with_floor(noisy, stderr, "bias-scale")
    assert result.scatter_floor_g == 0 and result.chi2_reduced_before < 1
