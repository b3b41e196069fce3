"""LM fit of Eq. 1: exact recovery, honest uncertainties, and refusal of designs that cannot see enough."""

import numpy as np
import pytest

from accelcal_rig.fit.lm import DegenerateDesign, fit_sfem, free_mask
from accelcal_rig.fit.sfem import correct, distort, norm_only_gauge
from accelcal_rig.plan import schedules
from accelcal_rig.sim.truth import truth_for_serial

TRUTH = truth_for_serial("LM-TEST").parameters_at(10.0)
NOISE_G = 12e-6


def test_noise_free_reference_fit_recovers_all_twelve() -> None:
    gravity = schedules.paper_24()
    fit = fit_sfem(distort(gravity, TRUTH), np.full((24, 3), NOISE_G), gravity, "reference")
    np.testing.assert_allclose(fit.parameters, TRUTH, atol=1e-10)
    assert fit.free.all() and np.all(np.isfinite(fit.sigma))


def test_noise_free_norm_only_fit_recovers_the_truth_in_its_gauge() -> None:
    gravity = schedules.paper_24()
    fit = fit_sfem(distort(gravity, TRUTH), np.full((24, 3), NOISE_G), None, "norm-only")
    np.testing.assert_allclose(fit.parameters, norm_only_gauge(TRUTH), atol=1e-10)
    assert np.all(np.isnan(fit.sigma[9:12])) and not fit.free[9:12].any()
    # |g| is what norm-only sees: it agrees with the truth for any direction
    directions = schedules.sphere(50)
    raw = distort(directions, TRUTH)
    np.testing.assert_allclose(np.linalg.norm(correct(raw, fit.parameters), axis=1), 1.0, atol=1e-10)


@pytest.mark.parametrize("mode", ["reference", "norm-only"])
def test_quoted_sigma_matches_the_scatter_of_repeated_fits(mode: str) -> None:
    gravity = schedules.paper_24()
    raw = distort(gravity, TRUTH)
    rng = np.random.default_rng(11)
    estimates, sigmas = [], []
    for _ in range(200):
        fit = fit_sfem(raw + rng.normal(0, NOISE_G, raw.shape), np.full((24, 3), NOISE_G),
                       gravity if mode == "reference" else None, mode)
        estimates.append(fit.parameters[fit.free])
        sigmas.append(fit.sigma[fit.free])
    truth = (TRUTH if mode == "reference" else norm_only_gauge(TRUTH))[free_mask(mode)]
    estimates, sigmas = np.array(estimates), np.array(sigmas)
    scatter = estimates.std(axis=0)
    ratio = np.median(sigmas, axis=0) / scatter
    assert np.all(np.abs(ratio - 1) < 0.25), ratio                                # σ is honest
    bias_z = (estimates.mean(axis=0) - truth) / (scatter / np.sqrt(len(estimates)))
    assert np.all(np.abs(bias_z) < 4), bias_z                                     # and unbiased


def test_weights_follow_each_poses_standard_error() -> None:
    gravity = schedules.paper_24()
    raw = distort(gravity, TRUTH)
    stderr = np.full((24, 3), NOISE_G)
    spoiled = raw.copy()
    spoiled[5] += 1e-3            # one pose 1 mg off...
    stderr[5] = 1.0               # ...but it says it is worthless
    fit = fit_sfem(spoiled, stderr, gravity, "reference")
    np.testing.assert_allclose(fit.parameters, TRUTH, atol=1e-8)


def test_too_few_poses_are_refused() -> None:
    gravity = schedules.six_position()
    with pytest.raises(DegenerateDesign, match="6 poses give 6 equations for 9 parameters in norm-only mode"):
        fit_sfem(distort(gravity, TRUTH), np.full((6, 3), NOISE_G), None, "norm-only")


def test_poses_about_one_axis_only_are_refused_by_name() -> None:
    gravity = schedules.paper_24()[:8]  # eight steps about z: gravity never leaves the x-y plane
    with pytest.raises(DegenerateDesign, match=r"the 8 poses cannot separate .*spread the poses over more axes"):
        fit_sfem(distort(gravity, TRUTH), np.full((8, 3), NOISE_G), gravity, "reference")


def test_bias_and_scale_alone_from_six_positions() -> None:
    truth = TRUTH.copy()
    truth[6:12] = 0.0  # a sensor with no cross-axis terms
    gravity = schedules.six_position()
    fit = fit_sfem(distort(gravity, truth), np.full((6, 3), NOISE_G), None, "norm-only", "bias-scale")
    np.testing.assert_allclose(fit.parameters, truth, atol=1e-10)
