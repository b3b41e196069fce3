"""Figures of merit: Eq. 9 RMSE of |g|, Eq. 10 tilt angles, drift over temperature, µg/K, noise floor."""

from __future__ import annotations

import numpy as np


def norm_rmse_mg(accel_g: np.ndarray, gravity_g: float = 1.0) -> float:
    """Eq. 9: RMS deviation of |a| from the site's gravity (in standard g) over all samples or poses, in mg."""
    deviation = np.linalg.norm(np.asarray(accel_g, dtype=float), axis=-1) - gravity_g
    return float(np.sqrt(np.mean(deviation**2)) * 1e3)


def tilt_angles_deg(accel_g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eq. 10: pitch φ = arctan(−Y / √(X² + Z²)) and roll θ = arctan(X / −Z), in degrees.

    Quadrant-safe forms of the same angles (arctan2), so a sensor upside down gives ±180° roll, not 0°.
    """
    a = np.asarray(accel_g, dtype=float)
    x, y, z = a[..., 0], a[..., 1], a[..., 2]
    pitch = np.degrees(np.arctan2(-y, np.hypot(x, z)))
    roll = np.degrees(np.arctan2(x, -z))
    return pitch, roll


def drift_mg(offset_g: np.ndarray) -> np.ndarray:
    """Per-axis max − min of zero-g offsets (n_temperatures, 3) over the temperature range, in mg."""
    offset_g = np.asarray(offset_g, dtype=float)
    return (offset_g.max(axis=0) - offset_g.min(axis=0)) * 1e3


def temperature_coefficient_ug_per_k(accel_g: np.ndarray, temperature_c: np.ndarray) -> np.ndarray:
    """Per-axis slope of a straight line through output against temperature, in µg/K."""
    temperature_c = np.asarray(temperature_c, dtype=float)
    design = np.column_stack([temperature_c - temperature_c.mean(), np.ones_like(temperature_c)])
    slope = np.linalg.lstsq(design, np.asarray(accel_g, dtype=float), rcond=None)[0][0]
    return slope * 1e6


def noise_floor_mg(mean_g: np.ndarray, stderr_g: np.ndarray) -> float:
    """The Eq. 9 RMSE that the per-pose standard errors alone would leave after a perfect fit, in mg.

    Each pose's |g| error is its per-axis standard errors projected on its direction.
    """
    mean_g = np.asarray(mean_g, dtype=float)
    direction = mean_g / np.linalg.norm(mean_g, axis=1, keepdims=True)
    variance = np.sum((direction * np.asarray(stderr_g, dtype=float)) ** 2, axis=1)
    return float(np.sqrt(variance.mean()) * 1e3)
