"""Against another tool: imucal's published calibration of a real IMU session (tests/data/real).

Six static poses (found here from the recording's labels) identify bias and scale from |g| alone; the
comparison is of those gauge-invariant quantities, and the 9-parameter fit must be refused.
"""

from __future__ import annotations

import csv
import itertools
import json

import numpy as np
import pytest

from accelcal_rig.fit.lm import DegenerateDesign, fit_sfem
from tests.conftest import REPO

DATA = REPO / "tests" / "data" / "real"  # imucal (MIT): see its README
COUNTS_PER_G_NOMINAL = 2048.0  # the recording's ADC: roughly 2045 counts per g


def static_poses() -> tuple[np.ndarray, np.ndarray]:
    with open(DATA / "imucal-annotated-session.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    means, stderrs = [], []
    for part, group in itertools.groupby(rows, key=lambda r: r["part"]):
        if part.endswith("_rot"):
            continue  # rotations are for the gyroscope
        counts = np.array([[float(r["acc_x"]), float(r["acc_y"]), float(r["acc_z"])] for r in group])
        g = counts / COUNTS_PER_G_NOMINAL
        means.append(g.mean(axis=0))
        stderrs.append(g.std(axis=0, ddof=1) / np.sqrt(len(g)))
    return np.array(means), np.array(stderrs)


@pytest.fixture(scope="module")
def poses() -> tuple[np.ndarray, np.ndarray]:
    if not (DATA / "imucal-annotated-session.csv").exists():
        pytest.fail(f"the real recording is missing: {DATA}")
    return static_poses()


def test_six_parameter_norm_only_fit_agrees_with_imucal(poses) -> None:
    mean, stderr = poses
    assert len(mean) == 6
    reference = json.loads((DATA / "imucal-reference-calibration.json").read_text())
    fit = fit_sfem(mean, stderr, None, "norm-only", "bias-scale")
    bias_counts = fit.parameters[0:3] * COUNTS_PER_G_NOMINAL
    counts_per_g = COUNTS_PER_G_NOMINAL / fit.parameters[3:6]
    reference_counts_per_g = np.diag(reference["K_a"]) * 9.81  # K_a is counts per m/s², g = 9.81 m/s²
    np.testing.assert_allclose(bias_counts, reference["b_a"], atol=0.6)                 # ≈ 0.3 mg
    np.testing.assert_allclose(counts_per_g / reference_counts_per_g, 1.0, atol=2.5e-4)


def test_nine_parameter_fit_on_six_poses_is_refused(poses) -> None:
    mean, stderr = poses
    with pytest.raises(DegenerateDesign, match="6 poses give 6 equations for 9 parameters"):
        fit_sfem(mean, stderr, None, "norm-only")
