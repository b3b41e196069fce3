"""Figures of merit on poses: exact on constructed errors."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from accelcal_rig.fit.verification import pose_figures, tilt_errors_deg, zero_g_offset_mg
from accelcal_rig.plan import schedules

GRAVITY = schedules.sphere(12)
STDERR = np.full((12, 3), 1e-5)


def figures(compensated: np.ndarray, setpoints: np.ndarray, align: bool = False) -> dict:
    reference = np.tile(GRAVITY, (len(setpoints) // 12, 1))
    return pose_figures(compensated, reference, np.tile(STDERR, (len(setpoints) // 12, 1)), setpoints,
                        setpoints + 0.1, align)


def test_a_perfect_calibration_has_no_error() -> None:
    result = figures(GRAVITY.copy(), np.full(12, 25.0))
    assert result["rmse_mg"] == pytest.approx(0, abs=1e-9) and result["max_axis_error_mg"] == pytest.approx(0, abs=1e-9)
    assert result["max_tilt_error_deg"] == pytest.approx(0, abs=1e-9) and result["n_poses"] == 12
    assert result["by_setpoint"][0]["temperature_c"] == pytest.approx(25.1)


def test_a_residual_bias_per_temperature_is_the_offset_and_its_span_the_drift() -> None:
    offsets = np.array([[0.02, 0.0, -0.01], [0.05, 0.01, 0.03]]) * 1e-3       # g at 20 and 40 °C
    compensated = np.vstack([GRAVITY + offsets[0], GRAVITY + offsets[1]])
    # A residual scale error must not pass for an offset: the line in each axis's gravity separates them.
    compensated = compensated * np.array([1 + 30e-6, 1, 1 - 20e-6])
    result = figures(compensated, np.repeat([20.0, 40.0], 12))
    np.testing.assert_allclose([r["offset_mg"] for r in result["by_setpoint"]], offsets * 1e3 *
                               np.array([1 + 30e-6, 1, 1 - 20e-6]), atol=1e-9)
    np.testing.assert_allclose(result["drift_mg"], [0.03, 0.01, 0.04], atol=1e-6)
    assert result["max_axis_error_mg"] == pytest.approx(np.max(np.abs(compensated - np.vstack([GRAVITY] * 2))) * 1e3)


def test_the_offset_of_a_line_is_its_value_at_zero_g() -> None:
    reference = np.linspace(-1, 1, 7)[:, None] * np.ones(3)
    error = 0.5 + 2.0 * reference
    np.testing.assert_allclose(zero_g_offset_mg(error, reference), [0.5, 0.5, 0.5])
    np.testing.assert_allclose(zero_g_offset_mg(error[:2], reference[:2]), error[:2].mean(axis=0))  # too few: mean


def test_tilt_error_of_a_small_turn_about_the_horizontal_is_its_angle() -> None:
    level = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    turned = Rotation.from_euler("x", [[0.01], [-0.02]], degrees=True).apply(level)  # pitch turns by the angle
    np.testing.assert_allclose(tilt_errors_deg(turned, level), [0.01, 0.02], rtol=1e-6)
    upright = np.array([[0.0, 1.0, 0.0]])  # gravity along y: roll is undefined and not judged
    np.testing.assert_allclose(tilt_errors_deg(Rotation.from_euler("y", 5, degrees=True).apply(upright), upright), 0,
                               atol=1e-9)


def test_norm_only_output_is_judged_after_the_rotation_it_cannot_know() -> None:
    turned = Rotation.from_euler("z", 2.0, degrees=True).apply(GRAVITY)
    raw = figures(turned, np.full(12, 25.0))
    aligned = figures(turned, np.full(12, 25.0), align=True)
    assert raw["max_axis_error_mg"] > 10 and aligned["max_axis_error_mg"] < 1e-6
    assert aligned["rmse_mg"] == pytest.approx(raw["rmse_mg"], abs=1e-9)  # a rotation does not change |g|
