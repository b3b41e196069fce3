"""The stated uncertainty against Monte Carlo: a calibration repeated with new noise puts 95 % of its held-out
errors inside the k = 2 interval; each source is what it says."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from accelcal_rig.fit.lm import fit_sfem
from accelcal_rig.fit.sfem import correct, distort
from accelcal_rig.fit.thermal import ThermalModel, fit_thermal
from accelcal_rig.fit.uncertainty import (
    COVERAGE_FACTOR,
    CoefficientCovariance,
    coefficient_covariance,
    combined,
    magnitude_noise_u,
    output_uncertainty,
    two_stage_map,
)
from accelcal_rig.plan import schedules
from accelcal_rig.sim.truth import truth_for_serial

TRUTH = truth_for_serial("ADX355-A002").parameters_at(25.0)
NOISE_G = 15e-6
ACCURACY_RAD = np.radians(10 / 3600)


def calibrate(rng: np.random.Generator) -> tuple[ThermalModel, CoefficientCovariance]:
    """One setpoint's reference fit of the 24 poses, as a degree-0 thermal model with its covariance."""
    gravity = schedules.paper_24()
    turned = Rotation.from_rotvec(rng.uniform(-ACCURACY_RAD, ACCURACY_RAD, (24, 3))).apply(gravity)
    raw = distort(turned, TRUTH) + rng.normal(0, NOISE_G, gravity.shape)
    stderr = np.full((24, 3), NOISE_G)
    fit = fit_sfem(raw, stderr, gravity, "reference", reference_accuracy_rad=ACCURACY_RAD)
    model = fit_thermal(np.array([25.0]), fit.parameters[None], fit.sigma[None], fit.free, 0)
    mapping = two_stage_map([fit.jacobian], np.zeros(1), fit.sigma[None], fit.free, 1)
    covariance = coefficient_covariance(mapping, gravity, stderr, ACCURACY_RAD, fit.free, 1, fit.residuals,
                                        np.zeros((1, 12)), fit.sigma[None])
    return model, covariance


def test_held_out_errors_fall_inside_the_expanded_uncertainty_95_percent_of_the_time() -> None:
    rng = np.random.default_rng(8)
    checks = schedules.sphere(12)
    inside = []
    for _ in range(200):
        model, covariance = calibrate(rng)
        reading = distort(checks, TRUTH) + rng.normal(0, NOISE_G, checks.shape)   # a new reading, new noise
        sources = output_uncertainty(reading, np.full(12, 25.0), model, covariance, np.full((12, 3), NOISE_G),
                                     np.zeros(12), 0.0)
        inside.append(np.abs(correct(reading, model.parameters_at(np.full(12, 25.0))) - checks)
                      <= COVERAGE_FACTOR * combined(sources))
    coverage = float(np.mean(inside))
    assert coverage == pytest.approx(0.9545, abs=0.012), coverage  # 200 × 36 axis errors: ±0.5 % (1σ, correlated)
    # The calibration's own share is real: leave it out and the interval is too short.
    assert sources["calibration_noise"].max() > 0.2 * sources["reading_noise"].max()
    assert sources["turntable_pointing"].max() > 0


def test_temperature_and_gravity_terms_are_their_derivatives_times_their_uncertainties() -> None:
    drifting = np.zeros((12, 2))
    drifting[:, 0] = [0, 0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0]
    drifting[2, 1] = 1e-3 * 50  # bias z: 1 mg per °C over the ±50 °C half-range
    model = ThermalModel((-25.0, 75.0), drifting, np.empty((0, 12)), 1)
    nothing = CoefficientCovariance(np.zeros(12, dtype=bool), 2, np.zeros((0, 0)), np.zeros((0, 0)),
                                    np.zeros((0, 0)), np.zeros(12))
    reading = np.array([[0.0, 0.0, 1.0]])
    sources = output_uncertainty(reading, np.array([25.0]), model, nothing, np.zeros((1, 3)), np.array([0.02]), 3e-5)
    np.testing.assert_allclose(sources["temperature"][0], [0, 0, 1e-3 * 0.02], atol=1e-12)
    np.testing.assert_allclose(sources["gravity"][0], [0, 0, 3e-5], rtol=1e-9)
    assert not sources["calibration_noise"].any() and not sources["thermal_model"].any()


def test_the_consistency_check_finds_95_percent_within_an_uncertainty_that_covers_and_fewer_within_one_that_does_not() -> None:
    """E_n = |error| / (k × √(u_cal² + u_meas²)): errors drawn with exactly the stated uncertainties fall within
    about 95 % of the time (k = 2); halve what is stated and the share drops to about 68 %."""
    from accelcal_rig.fit.uncertainty import consistency

    rng = np.random.default_rng(8)
    calibration_u, measurement_u = np.full((4000, 3), 0.003), np.full((4000, 3), 0.004)
    errors = rng.normal(0.0, 0.005, (4000, 3))
    covered = consistency(errors, calibration_u, measurement_u)
    assert covered["axis_errors"] == 12000 and 0.945 < covered["within_share"] < 0.96
    short = consistency(errors, calibration_u / 2, measurement_u / 2)
    assert 0.66 < short["within_share"] < 0.70 and short["largest_e_n"] > 2.0


def test_magnitude_noise_follows_the_coefficients_and_the_temperature_as_a_monte_carlo_does() -> None:
    """A check's |output| scatter from the calibration's noise (coefficients drawn from their covariance, their
    correlations kept) and from the noise of its temperature, against `magnitude_noise_u`'s linear propagation:
    within 5 % over 4000 draws (their own scatter ~1 %)."""
    truth = truth_for_serial("MC-0001")
    domain = (-40.0, 60.0)
    x = (np.linspace(*domain, 9) - 25.0) / 50.0
    per_parameter = np.array([np.polynomial.polynomial.polyfit(  # the truth's cubics over the domain's own x
        np.linspace(-1, 1, 9), np.polynomial.polynomial.polyval(x, c), 3) for c in truth.coefficients])
    model = ThermalModel(domain, per_parameter, np.zeros((1, 12)), 3)
    rng = np.random.default_rng(7)
    mixing = rng.normal(0.0, 2e-5, (48, 48))
    covariance = CoefficientCovariance(free=np.ones(12, dtype=bool), n_powers=4, noise=mixing @ mixing.T / 48,
                                       pointing=np.zeros((48, 48)), excess=np.zeros((48, 48)),
                                       model_variance=np.zeros(12))
    directions = schedules.sphere(6)
    temperature_c = np.array([-39.0, -5.0, 20.0, 45.0, 59.0, 59.5])
    raw = distort(directions, model.parameters_at(temperature_c))
    temperature_u_c = np.full(6, 0.4)
    predicted = magnitude_noise_u(raw, temperature_c, model, covariance, temperature_u_c, "clamp")

    draws = rng.multivariate_normal(np.zeros(48), covariance.noise, 4000)          # parameter-major, as flattened
    shifted = model.coefficients[None, :, :] + draws.reshape(4000, 12, 4)
    temperatures = temperature_c[None, :] + rng.normal(0.0, 0.4, (4000, 6))
    magnitudes = np.array([np.linalg.norm(correct(raw, ThermalModel(domain, c, np.zeros((1, 12)), 3).parameters_at(
        t, "extrapolate")), axis=1) for c, t in zip(shifted, temperatures)])
    np.testing.assert_allclose(magnitudes.std(axis=0), predicted, rtol=0.05)
