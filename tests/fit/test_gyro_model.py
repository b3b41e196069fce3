"""The rate-table gyroscope model: forward and inverse agree, its Jacobian is the model's derivative, and the
fixture's angular velocity follows the table's chain."""

from __future__ import annotations

import numpy as np

from accelcal_rig.config.rig import TurntableAxis
from accelcal_rig.fit import gyro_model
from accelcal_rig.plan.kinematics import TurntableKinematics


def _parameters(rng: np.random.Generator) -> np.ndarray:
    params = gyro_model.IDENTITY_PARAMETERS + rng.normal(0.0, 0.005, gyro_model.N_PARAMETERS)
    params[gyro_model.BIAS] = rng.normal(0.0, 0.5, 3)
    return params


def test_correcting_a_distorted_rate_gives_the_rate_back() -> None:
    rng = np.random.default_rng(3)
    params = _parameters(rng)
    rate, force = rng.normal(0.0, 600.0, (200, 3)), rng.normal(0.0, 1.0, (200, 3))
    raw = gyro_model.distort_rate(rate, force, params)
    assert np.max(np.abs(raw - rate)) > 1.0                         # the model does distort
    np.testing.assert_allclose(gyro_model.correct_rate(raw, force, params), rate, atol=1e-9)


def test_the_jacobian_is_the_models_derivative() -> None:
    rng = np.random.default_rng(4)
    params = _parameters(rng)
    rate, force = rng.normal(0.0, 300.0, (30, 3)), rng.normal(0.0, 1.0, (30, 3))
    analytic = gyro_model.distort_jacobian(rate, force, params)
    step = 1e-7
    numeric = np.stack([(gyro_model.distort_rate(rate, force, params + step * e)
                         - gyro_model.distort_rate(rate, force, params - step * e)) / (2 * step)
                        for e in np.eye(gyro_model.N_PARAMETERS)], axis=-1)
    np.testing.assert_allclose(analytic, numeric, atol=1e-5 * np.abs(numeric).max())


def test_asymmetry_and_nonlinearity_mean_what_their_names_say() -> None:
    params = gyro_model.IDENTITY_PARAMETERS.copy()
    params[gyro_model.ASYMMETRY.start] = 1e-3          # x: +0.1 % for positive rates, −0.1 % for negative
    params[gyro_model.NONLINEARITY.start + 1] = 2e-3   # y: +0.2 % of scale at 1000 °/s
    raw = gyro_model.distort_rate(np.array([[500.0, 0, 0], [-500.0, 0, 0], [0, 1000.0, 0]]), np.zeros(3), params)
    assert abs(raw[0, 0] / 500.0 - 1.001) < 1e-12
    assert abs(raw[1, 0] / -500.0 - 0.999) < 1e-12
    assert abs(raw[2, 1] / 1000.0 - 1.002) < 1e-12


def test_the_fixture_turns_as_the_chain_of_axes_says() -> None:
    axes = [TurntableAxis(name=n, axis=a, continuous=True) for n, a in
            (("outer", (0, 0, 1)), ("middle", (1, 0, 0)), ("inner", (0, 0, 1)))]
    kinematics = TurntableKinematics(axes)
    angles, rates = np.array([20.0, 70.0, -35.0]), np.array([3.0, -2.0, 5.0])
    step = 1e-6
    chain, later = kinematics.chain_matrices(angles), kinematics.chain_matrices(angles + rates * step)
    skew = chain.T @ (later - chain) / step                          # Rᵀ Ṙ = [ω]× in the fixture frame
    numeric = np.degrees([skew[2, 1], skew[0, 2], skew[1, 0]])
    np.testing.assert_allclose(kinematics.angular_velocity_in_fixture(angles, rates), numeric, rtol=1e-5)
    # Turning only the vertical outer axis turns the fixture about its own "up", whatever the others hold.
    up = kinematics.gravity_in_fixture(angles)
    np.testing.assert_allclose(kinematics.angular_velocity_in_fixture(angles, [7.0, 0, 0]), 7.0 * up, atol=1e-12)
