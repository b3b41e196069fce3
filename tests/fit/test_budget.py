"""The budget's sources where Eq. 1 × a polynomial in temperature is not the whole sensor: a joint fit's
fitted hysteresis and rate terms are no scatter, the hysteresis it measured is a source, a misfit is stated
where it is, and what a calibration cannot measure is said, not counted as zero."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.fit.budget import FittedTerms, band_misfit, hysteresis_u_g, not_included
from accelcal_rig.fit.options import FitOptions
from accelcal_rig.fit.sfem import correct, distort
from accelcal_rig.fit.uncertainty import COVERAGE_FACTOR, CoefficientCovariance, model_variance
from accelcal_rig.plan.schedules import sphere
from accelcal_rig.sim.truth import truth_for_serial
from accelcal_rig.store.read import VectorPoses

from .vector_poses import accel_poses, fit_accelerometer

TRUTH = truth_for_serial("ADX355-A002")
NOISE_G = 5e-6
POSES_PER_BAND = 12
#: Clock seconds per pose while the temperature moves (12 poses move a band's 2 °C at the rate).
POSE_S = 10.0


def ramp_poses(centres_c: list[float], rates_c_per_min: list[float], approach: list[float], shift_g: np.ndarray,
               seed: int) -> VectorPoses:
    """Bands of POSES_PER_BAND evenly spread poses, each band centred on its temperature and moving at its
    rate while measured, each pose's reading Eq. 1 of the truth plus `shift_g` (per band, (K, 3)) and noise."""
    rng = np.random.default_rng(seed)
    directions = sphere(POSES_PER_BAND)
    label, t, temperature, rate, side = [], [], [], [], []
    clock = 0.0
    for k, (centre, band_rate, band_side) in enumerate(zip(centres_c, rates_c_per_min, approach)):
        offsets = (np.arange(POSES_PER_BAND) - (POSES_PER_BAND - 1) / 2) * POSE_S
        t.append(clock + offsets + POSES_PER_BAND * POSE_S)
        temperature.append(centre + band_rate / 60.0 * offsets)
        label.append(np.full(POSES_PER_BAND, float(k)))
        rate.append(np.full(POSES_PER_BAND, band_rate))
        side.append(np.full(POSES_PER_BAND, band_side))
        clock += 4 * POSES_PER_BAND * POSE_S
    temperature_c = np.concatenate(temperature)
    reference = np.tile(directions, (len(centres_c), 1))
    parameters = TRUTH.parameters_at(temperature_c)
    readings = distort(reference, parameters) + np.repeat(shift_g, POSES_PER_BAND, axis=0)
    readings += rng.normal(0.0, NOISE_G, readings.shape)
    n = len(temperature_c)
    return accel_poses("ADX355-A002", 2.0, 3.9e-6, np.concatenate(label), np.concatenate(t), temperature_c, readings,
                    np.full((n, 3), NOISE_G), reference, 0.0, parameters, np.zeros(n, dtype=bool),
                    truth_gravity_g=reference, approach=np.concatenate(side), rate_c_per_min=np.concatenate(rate))


def bidirectional(h_g: np.ndarray, c_g: np.ndarray, seed: int) -> VectorPoses:
    """Down 55 → −35 at −2 °C/min, a band at rest at −40, up −30 → 50 at +2 °C/min: ±h by direction, c × rate."""
    down, up = [55.0 - 10 * k for k in range(10)], [-30.0 + 10 * k for k in range(9)]
    centres = down + [-40.0] + up
    rates = [-2.0] * len(down) + [0.0] + [2.0] * len(up)
    sides = [-1.0] * (len(down) + 1) + [1.0] * len(up)
    shift = np.array(sides)[:, None] * h_g + np.array(rates)[:, None] * c_g
    return ramp_poses(centres, rates, sides, shift, seed)


def test_a_joint_fits_hysteresis_and_rate_terms_are_no_scatter_and_its_hysteresis_is_a_source() -> None:
    h_g, c_g = np.array([0.05e-3, -0.08e-3, 0.03e-3]), np.array([0.1e-3, -0.05e-3, 0.08e-3])
    result = fit_accelerometer(bidirectional(h_g, c_g, seed=2), FitOptions(temperature_model="joint", hysteresis="on"))
    budget = result.figures["uncertainty_budget"]
    # What the fit took off the readings is not left in its residuals: they are the noise's alone.
    assert budget["sources_mg"]["scatter_beyond_noise"] == [0.0, 0.0, 0.0]
    assert max(budget["sources_mg"]["thermal_model"]) < 0.005
    # A reading at rest lies on one branch, ±h from the calibration: ĥ, and what is not known of it, u(ĥ),
    # which is what ĥ misses h by.
    found = np.abs(result.figures["hysteresis_mg"]) / 2
    hysteresis = np.array(budget["sources_mg"]["hysteresis"])
    u_found = np.sqrt(hysteresis**2 - found**2)
    assert np.all(hysteresis > found) and np.all(u_found < 0.2 * np.abs(h_g) * 1e3)
    assert np.all(np.abs(found - np.abs(h_g) * 1e3) < 2 * u_found)
    assert list(budget["sources_mg"]).index("hysteresis") == list(budget["sources_mg"]).index("thermal_model") + 1
    assert budget["not_included"] == {}


def test_a_fit_that_cannot_measure_the_hysteresis_or_the_rate_says_so_and_states_no_zero() -> None:
    h_g, c_g = np.array([0.05e-3, -0.08e-3, 0.03e-3]), np.array([0.1e-3, -0.05e-3, 0.08e-3])
    result = fit_accelerometer(bidirectional(h_g, c_g, seed=3), FitOptions(temperature_model="joint", hysteresis="off"))
    budget = result.figures["uncertainty_budget"]
    assert "hysteresis" not in budget["sources_mg"]
    assert set(budget["not_included"]) == {"hysteresis", "rate_of_change"}
    assert "2.00 °C/min" in budget["not_included"]["rate_of_change"]
    # Soaked poses (no rate to speak of): only the hysteresis is left unmeasured.
    soaked = ramp_poses([-40.0, -10.0, 20.0, 50.0], [0.0] * 4, [1.0] * 4, np.zeros((4, 3)), seed=4)
    covariance = CoefficientCovariance(np.ones(12, dtype=bool), 1, np.zeros((12, 12)), np.zeros((12, 12)),
                                       np.zeros((12, 12)), np.zeros(12))
    assert set(not_included(soaked, covariance)) == {"hysteresis"}


def test_a_one_way_ramps_misfit_at_its_soaked_ends_is_stated_there_and_covers_a_reading_at_rest() -> None:
    """Calibration poses on a ramp at 0.5 °C/min carry c × 0.5 °C/min, the ends soaked at rest carry none: no
    cubic follows both, and the readings at rest at the ends are missed by as much as the ends' bands show."""
    centres = [-40.0] + [-35.0 + 5 * k for k in range(18)] + [60.0]
    rates = [0.0] + [0.5] * 18 + [0.0]
    c_g = np.array([0.1e-3, -0.12e-3, 0.08e-3])
    poses = ramp_poses(centres, rates, [1.0] * len(centres), np.array(rates)[:, None] * c_g, seed=5)
    result = fit_accelerometer(poses, FitOptions(temperature_model="joint"))
    rows = {round(r["temperature_c"]): r["sources_mg"]["thermal_model"]
            for r in result.figures["uncertainty_budget"]["by_temperature"]}
    assert max(rows[-40]) > 0.01 and max(rows[60]) > 0.01        # mg: where the model misses …
    assert max(rows[10]) < 0.5 * max(rows[-40])                     # … not spread over the range
    # A new reading at rest at each end, against the truth: inside the expanded uncertainty.
    from accelcal_rig.fit.budget import calibration_covariance
    from accelcal_rig.fit.uncertainty import combined, output_uncertainty

    directions, rng = sphere(POSES_PER_BAND), np.random.default_rng(8)
    for end in (-40.0, 60.0):
        reading = distort(directions, TRUTH.parameters_at(np.full(len(directions), end)))
        reading += rng.normal(0.0, NOISE_G, reading.shape)
        at = np.full(len(directions), end)
        groups = [np.flatnonzero(poses.setpoint_c == s) for s in dict.fromkeys(poses.setpoint_c.tolist())]
        covariance = calibration_covariance(poses, groups, result.detail.fits, result.thermal, result.detail.temperatures_c,
                                            poses.temperature_c, "reference", True)
        u = combined(output_uncertainty(reading, at, result.thermal, covariance, np.full(reading.shape, NOISE_G),
                                        np.zeros(len(at)), 0.0))
        error = correct(reading, result.thermal.parameters_at(at)) - directions
        assert np.mean(np.abs(error) <= COVERAGE_FACTOR * u) > 0.9, end


def test_a_misfit_is_stated_where_it_is_and_noise_is_not_a_misfit() -> None:
    rng = np.random.default_rng(6)
    free = np.ones(12, dtype=bool)
    sigma = np.full((11, 12), 1e-5)
    residuals = rng.normal(0.0, 1e-5, (11, 12)) * 0.8            # what noise leaves about a fitted polynomial
    residuals[0, 0] = 2e-4                                        # one end missed on the bias x
    variance, local = model_variance(residuals, sigma, free, 4, sigma * 0.8)
    assert variance[0] > 0 and np.all(variance[1:] == 0)          # only the evident misfit counts
    assert local[0, 0] == pytest.approx(2e-4**2 - (0.8e-5) ** 2) and np.all(local[1:, 0] < 0.1 * local[0, 0])
    temperatures = np.linspace(-40.0, 60.0, 11)
    covariance = CoefficientCovariance(free, 4, np.zeros((48, 48)), np.zeros((48, 48)), np.zeros((48, 48)), variance,
                                       model_temperatures_c=temperatures[::-1], model_variance_by_temperature=local[::-1])
    at = covariance.model_variance_at(np.array([-50.0, -40.0, -35.0, 60.0]))
    assert at[0, 0] == at[1, 0] == local[0, 0]                    # beyond the ends: the nearest one's
    assert at[2, 0] == pytest.approx(0.5 * (local[0, 0] + local[1, 0]))
    unknown = CoefficientCovariance(free, 4, np.zeros((48, 48)), np.zeros((48, 48)), np.zeros((48, 48)), variance)
    np.testing.assert_array_equal(unknown.model_variance_at(np.array([0.0, 30.0])), [variance, variance])


def test_a_bands_common_offset_is_found_and_what_the_fit_takes_of_it_is_not_counted_as_noise() -> None:
    rng = np.random.default_rng(7)
    bands = [np.hstack([rng.normal(size=(36, 3)), np.zeros((36, 0))]) for _ in range(5)]
    whole = np.hstack([np.vstack(bands), np.ones((180, 1))])      # the fit's own columns: one shared constant
    offsets_true = np.array([3.0, -2.0, 0.5]) * 0.01
    residuals = np.concatenate([b @ offsets_true if k == 2 else np.zeros(36) for k, b in enumerate(bands)])
    offsets, sigma, left = band_misfit(residuals, whole, bands)
    np.testing.assert_allclose(offsets[2, 0:3], offsets_true, atol=1e-12)
    assert np.all(offsets[[0, 1, 3, 4], 0:3] == 0) and np.all(offsets[:, 3:] == 0)
    assert np.all(left[:, 0:3] <= sigma[:, 0:3] + 1e-15) and np.all(left[:, 0:3] > 0.5 * sigma[:, 0:3])


def test_a_reading_on_either_branch_is_h_from_the_calibration_and_an_estimate_adds_its_own_uncertainty() -> None:
    np.testing.assert_allclose(hysteresis_u_g(np.array([3e-5, -4e-5, 0.0]), np.array([0.0, 9e-10, 1e-10])),
                               [3e-5, 5e-5, 1e-5])
    terms = FittedTerms(np.array([1.0, -1.0]), np.array([1e-4, 0, 0]), np.array([2.0, 0.0]), np.array([0, 1e-5, 0]))
    np.testing.assert_allclose(terms.shift_g(), [[1e-4, 2e-5, 0], [-1e-4, 0, 0]])
