"""A bidirectional ramp's poses: from which side each was approached, and the joint fit's hysteresis term."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.fit.approach import approach_directions
from accelcal_rig.fit.joint import fit_joint
from accelcal_rig.fit.sfem import distort
from accelcal_rig.fit.thermal import ThermalModel
from accelcal_rig.plan.schedules import sphere


def test_the_direction_of_approach_is_read_off_the_temperature_history() -> None:
    t = np.arange(0.0, 20000.0, 60.0)
    temperature = np.interp(t, [0, 3000, 6000, 12000, 13000, 20000], [23, -40, -40, 60, 60, -35])  # cool, hold, …
    poses = t[5::10]  # none exactly at a corner of the history
    directions = approach_directions(poses, np.interp(poses, t, temperature), t, temperature)
    expected = np.select([poses < 3000, poses < 6000, poses < 12000, poses < 13000], [-1, -1, 1, 1], -1)
    assert np.array_equal(directions, expected)  # held temperatures keep the direction they were reached from


def synthetic_ramp(h_g: np.ndarray, seed: int) -> tuple[ThermalModel, ThermalModel, np.ndarray, np.ndarray,
                                                        np.ndarray, np.ndarray]:
    """A sensor whose bias drifts linearly, read on a ramp up and down with ±h by direction."""
    rng = np.random.default_rng(seed)
    truth = np.zeros((12, 2))
    truth[:, 0] = np.repeat([0.0, 1.0, 0.0, 0.0], 3) + rng.normal(0, 1e-3, 12)
    truth[0:3, 1] = [5e-3, -4e-3, 6e-3]
    model = ThermalModel((-40.0, 60.0), truth, np.empty((0, 12)), 1)
    directions = sphere(12)
    up, down = np.linspace(-40, 60, 11), np.linspace(55, -35, 10)
    temperature = np.repeat(np.concatenate([up, down]), len(directions))
    approach = np.repeat(np.concatenate([np.ones(len(up)), -np.ones(len(down))]), len(directions))
    reference = np.tile(directions, (len(up) + len(down), 1))
    readings = distort(reference, model.parameters_at(temperature)) + approach[:, None] * h_g
    readings += rng.normal(0, 5e-6, readings.shape)
    start = ThermalModel(model.domain_c, truth + rng.normal(0, 1e-4, truth.shape), np.empty((0, 12)), 1)
    return model, start, temperature, readings, reference, approach


def test_the_joint_fit_finds_the_hysteresis_and_the_mean_of_both_directions() -> None:
    h_g = np.array([0.1e-3, -0.2e-3, 0.05e-3])
    truth, start, temperature, readings, reference, approach = synthetic_ramp(h_g, seed=1)
    stderr = np.full(readings.shape, 5e-6)
    free = np.ones(12, dtype=bool)
    fitted, found_h, _, _ = fit_joint(start, free, temperature, readings, stderr, reference, "reference", 0.0, 1.0, approach)
    np.testing.assert_allclose(found_h, h_g, atol=3e-6)
    blind, none_h, _, _ = fit_joint(start, free, temperature, readings, stderr, reference, "reference", 0.0, 1.0)
    assert np.array_equal(none_h, np.zeros(3))
    truth_bias = truth.parameters_at(temperature)[:, :3]  # the blind fit's bias is pulled towards ±h
    aware_error = np.abs(fitted.parameters_at(temperature)[:, :3] - truth_bias).max()
    blind_error = np.abs(blind.parameters_at(temperature)[:, :3] - truth_bias).max()
    # Both directions over the same range: ±h cancels in the blind fit's bias to first order too, but its
    # residuals carry it, and only the aware fit says how large it is.
    assert aware_error < 3e-6 and blind_error < 0.2 * np.abs(h_g).max()
    from accelcal_rig.fit.sfem import correct

    def residual_rms(model: ThermalModel, h: np.ndarray) -> float:
        corrected = correct(readings - approach[:, None] * h, model.parameters_at(temperature))
        return float(np.sqrt(np.mean((corrected - reference) ** 2)))

    assert residual_rms(fitted, found_h) < 1e-5 < 0.3 * np.abs(h_g).max() < residual_rms(blind, none_h)


def test_poses_approached_one_way_only_fit_no_hysteresis_term() -> None:
    """±h and the constant bias cannot be told apart from one direction: the term is left out, not fitted
    to an arbitrary split (a campaign stopped before its way back)."""
    from dataclasses import replace

    from accelcal_rig.fit.vector_model import _both_ways
    from tests.fit.vector_poses import accel_poses

    n = 30
    base = accel_poses("X", 2.0, 1e-6, np.zeros(n), np.arange(n, dtype=float), np.linspace(-40, 60, n),
                    np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)), 3.0, None, np.zeros(n, dtype=bool))
    assert _both_ways(replace(base, approach=-np.ones(n))) is None
    split = np.where(np.arange(n) < n // 2, -1.0, 1.0)  # cooling over −40…10, warming over 10…60: no overlap
    assert _both_ways(replace(base, approach=split)) is None
    both = np.where(np.arange(n) % 2, -1.0, 1.0)
    assert np.array_equal(_both_ways(replace(base, approach=both)), both)


def test_the_rate_term_tells_what_follows_the_rate_from_a_hysteresis_that_stays_at_rest() -> None:
    """Readings biased by c × rate on the ramps and ±h by direction, with bands at rest (rate 0) at the ends:
    the joint fit finds both, and the calibration is the sensor at rest."""
    truth, start, temperature, readings, reference, approach = synthetic_ramp(np.zeros(3), seed=3)
    rate = approach * 2.0  # °C/min on the ramps …
    rest = (temperature == temperature.min()) | (temperature == temperature.max())
    rate[rest] = 0.0  # … and none where it soaked
    h_g, c_g = np.array([0.05e-3, -0.1e-3, 0.08e-3]), np.array([0.1e-3, 0.05e-3, -0.12e-3])
    readings = readings + approach[:, None] * h_g + rate[:, None] * c_g
    stderr = np.full(readings.shape, 5e-6)
    fitted, found_h, found_c, _ = fit_joint(start, np.ones(12, dtype=bool), temperature, readings, stderr, reference,
                                         "reference", 0.0, 1.0, approach, rate)
    np.testing.assert_allclose(found_h, h_g, atol=5e-6)
    np.testing.assert_allclose(found_c, c_g, atol=3e-6)
    assert np.abs(fitted.parameters_at(temperature)[:, :3] - truth.parameters_at(temperature)[:, :3]).max() < 5e-6


def test_a_poses_rate_of_change_is_centred_on_it_and_does_not_lag_at_a_turn() -> None:
    from accelcal_rig.fit.approach import temperature_rates_c_per_min

    t = np.arange(0.0, 7200.0, 10.0)
    temperature = np.interp(t, [0, 3000, 3600, 7200], [60, -40, -40, 20])  # 2 °C/min down, held, 1 °C/min up
    poses = np.array([1500.0, 3300.0, 5400.0])
    rates = temperature_rates_c_per_min(poses, np.interp(poses, t, temperature), t, temperature)
    np.testing.assert_allclose(rates, [-2.0, 0.0, 1.0], atol=1e-9)  # mid-hold: 0, though cooled 10 min before


def test_hysteresis_state_swings_over_its_span():
    """The stop operator: +1 after warming through the span, −1 after cooling through it, half-way between
    5 °C after a turn for a span of 10 °C, held at ±1 at rest."""
    from accelcal_rig.fit.approach import hysteresis_states

    t = np.arange(0.0, 9000.0, 30.0)
    temperature = np.interp(t, [0, 1800, 3600, 6000, 9000], [20, 60, 60, 20, 20])  # warm, rest, cool, rest
    poses_t = np.array([3000.0, 3600.0 + 5 / 40 * 2400 + 60, 5900.0, 8000.0])
    states = hysteresis_states(poses_t, np.interp(poses_t, t, temperature), t, temperature, ((10.0, None),))[0]
    assert states[0] == 1.0 and states[2] == -1.0 and states[3] == -1.0
    assert abs(states[1]) < 0.2  # 5 °C of cooling after the turn (the readings averaged ±60 s)


def test_hysteresis_state_relaxes_at_rest_with_its_time_constant():
    """A relaxing candidate: after warming through the span it falls towards the middle at rest, to e⁻¹ of
    where it was after one time constant; a held one stays at +1."""
    from accelcal_rig.fit.approach import hysteresis_states

    t = np.arange(0.0, 12000.0, 30.0)
    temperature = np.interp(t, [0, 1800, 12000], [20, 60, 60])  # warm, then rest for 2.8 h
    rested_s = 3600.0
    poses_t = np.array([1800.0 + 120.0, 1800.0 + 120.0 + rested_s])  # the average of ±60 s has settled by then
    held, relaxing = hysteresis_states(poses_t, np.interp(poses_t, t, temperature), t, temperature,
                                       ((10.0, None), (10.0, 1.0)))
    np.testing.assert_allclose(held, [1.0, 1.0])
    assert relaxing[1] / relaxing[0] == pytest.approx(np.exp(-1.0), rel=1e-6)
