import numpy as np

from accelcal_rig.fit.metrics import (
    drift_mg,
    noise_floor_mg,
    norm_rmse_mg,
    temperature_coefficient_ug_per_k,
    tilt_angles_deg,
)


def test_eq9_rmse_of_the_norm() -> None:
    np.testing.assert_allclose(norm_rmse_mg(np.array([[0, 0, 1.001], [0, 0.999, 0]])), 1.0, rtol=1e-9)
    assert norm_rmse_mg(np.eye(3)) == 0.0


def test_eq10_tilt_angles() -> None:
    # The paper's convention: level reads Z = −1 g; pitch φ = arctan(−Y/√(X²+Z²)), roll θ = arctan(X / −Z)
    pitch, roll = tilt_angles_deg(np.array([[0.0, 0.0, -1.0],
                                            [0.0, -np.sin(np.radians(30)), -np.cos(np.radians(30))],
                                            [np.sin(np.radians(15)), 0.0, -np.cos(np.radians(15))]]))
    np.testing.assert_allclose(pitch, [0, 30, 0], atol=1e-12)
    np.testing.assert_allclose(roll, [0, 0, 15], atol=1e-12)


def test_drift_is_max_minus_min_per_axis() -> None:
    np.testing.assert_allclose(drift_mg(np.array([[0.001, 0, -0.002], [0.004, 0, 0.001]])), [3, 0, 3])


def test_temperature_coefficient_in_micro_g_per_kelvin() -> None:
    temperature = np.linspace(20, 60, 41)
    output = np.column_stack([1346e-6 * temperature, -37e-6 * temperature, np.full(41, 0.5)])
    np.testing.assert_allclose(temperature_coefficient_ug_per_k(output, temperature), [1346, -37, 0], atol=1e-9)


def test_noise_floor_projects_each_axis_error_on_the_pose_direction() -> None:
    mean = np.array([[0, 0, 1.0], [1.0, 0, 0]])
    stderr = np.array([[5e-6, 5e-6, 1e-5], [1e-5, 7e-6, 7e-6]])  # only the component along g matters
    np.testing.assert_allclose(noise_floor_mg(mean, stderr), 0.01)
