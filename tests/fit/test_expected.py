"""The expected in-sample |g| RMSE against Monte Carlo: fits of noisy poses reach what it says, below the
noise floor by the degrees of freedom they use."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from accelcal_rig.fit.expected import expected_norm_rmse_mg, expected_reference_rmse_mg, thermal_jacobian
from accelcal_rig.fit.lm import fit_sfem, norm_sigma
from accelcal_rig.fit.metrics import noise_floor_mg, norm_rmse_mg
from accelcal_rig.fit.sfem import correct, distort
from accelcal_rig.plan import schedules
from accelcal_rig.sim.truth import truth_for_serial

TRUTH = truth_for_serial("ADX355-A001").parameters_at(25.0)
NOISE_G = 20e-6


@pytest.mark.parametrize(("mode", "accuracy_arcsec"), [("reference", 0.0), ("reference", 20.0), ("norm-only", 0.0)])
def test_fits_reach_the_expected_rmse_not_the_noise_floor(mode: str, accuracy_arcsec: float) -> None:
    gravity = schedules.paper_24()
    accuracy_rad = np.radians(accuracy_arcsec / 3600)
    stderr = np.full((24, 3), NOISE_G)
    rng = np.random.default_rng(5)
    squares, expected = [], []
    for _ in range(300):
        # The table points each pose a little off: a rotation uniform within ± the accuracy about each axis.
        turned = Rotation.from_rotvec(rng.uniform(-accuracy_rad, accuracy_rad, (24, 3))).apply(gravity)
        raw = distort(turned, TRUTH) + rng.normal(0, NOISE_G, gravity.shape)
        fit = fit_sfem(raw, stderr, gravity if mode == "reference" else None, mode,
                       reference_accuracy_rad=accuracy_rad)
        squares.append(norm_rmse_mg(correct(raw, fit.parameters)) ** 2)
        expected.append(expected_reference_rmse_mg(fit.jacobian, gravity, stderr, accuracy_rad) if mode == "reference"
                        else expected_norm_rmse_mg(fit.jacobian, norm_sigma(raw, stderr)))
    observed = np.sqrt(np.mean(squares))
    floor = noise_floor_mg(raw, stderr)
    assert observed == pytest.approx(np.mean(expected), rel=0.04)
    if accuracy_arcsec == 0:
        assert np.mean(expected) < 0.95 * floor  # the fit beats the floor in-sample
    else:  # the pointing error, blind to |g| before the fit, leaks into it through the fit
        assert np.mean(expected) > np.mean(expected_without_pointing(gravity, stderr))
    if mode == "norm-only":  # 9 parameters from 24 equations: √(15/24) of the floor
        assert np.mean(expected) == pytest.approx(floor * np.sqrt(15 / 24), rel=0.02)


def expected_without_pointing(gravity: np.ndarray, stderr: np.ndarray) -> float:
    fit = fit_sfem(distort(gravity, TRUTH), stderr, gravity, "reference")
    return expected_reference_rmse_mg(fit.jacobian, gravity, stderr, 0.0)


def test_the_thermal_jacobian_spreads_each_parameter_over_its_powers() -> None:
    jacobian = np.arange(2 * 3 * 2, dtype=float).reshape(6, 2)        # 2 poses × 3 rows, 2 parameters
    powers = np.array([[1.0, 0.5], [1.0, -1.0]])                      # x = 0.5 and −1, degree 1
    combined = thermal_jacobian([jacobian], [powers], 3)
    assert combined.shape == (6, 4)
    np.testing.assert_allclose(combined[:3, [0, 2]], jacobian[:3])     # power 0 of each parameter
    np.testing.assert_allclose(combined[3:, 1], -jacobian[3:, 0])      # power 1 at x = −1
