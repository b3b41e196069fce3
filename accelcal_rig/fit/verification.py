"""How good a calibration is, judged on poses: |g| RMSE (Eq. 9), each axis's error against the reference
gravity, Eq. 10 tilt errors, and the residual zero-g drift over temperature.

The same figures serve the verification poses (never fitted: the figures that count) and, beside them,
the calibration poses (in-sample: a fit with as many parameters as data can beat its own noise there).
Arrays in, a plain dict out.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from scipy.spatial.transform import Rotation

from accelcal_rig.fit.lm import pointing_covariance_g2
from accelcal_rig.fit.metrics import noise_floor_mg, norm_rmse_mg, tilt_angles_deg
from accelcal_rig.fit.uncertainty import COVERAGE_FACTOR

#: Roll (Eq. 10) is judged only where gravity has at least this much in the x–z plane, in g: near ±90° of
#: pitch roll is undefined and any error in it is meaningless.
ROLL_DEFINED_G = 0.5


def pose_figures(compensated_g: np.ndarray, reference_g: np.ndarray, stderr_g: np.ndarray, setpoint_c: np.ndarray,
                 temperature_c: np.ndarray, align: bool, gravity_g: float = 1.0,
                 reference_u: ReferenceUncertainty | None = None, milli: str = "mg",
                 angle: AngleFigure = "tilt") -> dict[str, Any]:
    """The figures of merit of compensated readings (N, 3) against the gravity each pose expects (N, 3).

    `align`: a norm-only fit fixes no rotation of the sensor frame, so its output is first turned by the one
    rotation that best aligns it with the references (per-axis and tilt errors are then those of a sensor
    mounted as the fit found it). `gravity_g`: the site's gravity in standard g, what |g| is judged against.
    `reference_u`: the references' uncertainty, to state each figure's own (`expanded_u`, what a limit on it
    is judged with). Any three-axis channel against its reference vector: figures in thousandths of its unit
    (`milli`: mg for an accelerometer in g), and its angle figure (`angle`): gravity's Eq. 10 tilt, or the
    direction's error of any other vector.
    """
    compensated_g = np.asarray(compensated_g, dtype=float)
    reference_g = np.asarray(reference_g, dtype=float)
    if align:
        rotation, _ = Rotation.align_vectors(reference_g, compensated_g)
        compensated_g = rotation.apply(compensated_g)
    error_mg = (compensated_g - reference_g) * 1e3
    groups = [np.flatnonzero(setpoint_c == s) for s in dict.fromkeys(np.asarray(setpoint_c).tolist())]
    by_setpoint = [{
        "setpoint_c": float(setpoint_c[g[0]]), "temperature_c": float(np.mean(temperature_c[g])),
        "n_poses": int(len(g)), f"rmse_{milli}": norm_rmse_mg(compensated_g[g], gravity_g),
        f"max_axis_error_{milli}": float(np.max(np.abs(error_mg[g]))),
        f"offset_{milli}": zero_g_offset_mg(error_mg[g], reference_g[g]).tolist(),
    } for g in groups]
    offsets = np.array([row[f"offset_{milli}"] for row in by_setpoint])
    angles = ANGLE_ERRORS[angle]
    figures = {
        "n_poses": int(len(compensated_g)),
        f"rmse_{milli}": norm_rmse_mg(compensated_g, gravity_g),
        f"noise_floor_{milli}": noise_floor_mg(compensated_g, stderr_g),
        f"max_axis_error_{milli}": float(np.max(np.abs(error_mg))),
        f"rms_axis_error_{milli}": np.sqrt(np.mean(error_mg**2, axis=0)).tolist(),
        f"max_{angle}_error_deg": float(np.max(angles(compensated_g, reference_g))),
        f"drift_{milli}": (offsets.max(axis=0) - offsets.min(axis=0)).tolist(),
        "frame": "best rotation onto the references (norm-only fits fix none)" if align else "fixture",
        "by_setpoint": by_setpoint,
    }
    if reference_u is not None:
        figures["expanded_u"] = figure_uncertainty(compensated_g, reference_g, stderr_g, groups, offsets, reference_u,
                                                   milli, angle)
    return figures


@dataclass(frozen=True)
class ReferenceUncertainty:
    """What a verification pose's reference is known to: the table's pointing (± per axis, uniform) and the
    site's gravity (relative standard uncertainty)."""

    accuracy_rad: float
    gravity_relative_u: float


def figure_uncertainty(compensated_g: np.ndarray, reference_g: np.ndarray, stderr_g: np.ndarray,
                       groups: list[np.ndarray], offsets_mg: np.ndarray, reference_u: ReferenceUncertainty,
                       milli: str = "mg", angle: AngleFigure = "tilt") -> dict[str, Any]:
    """U (k = 2) of each figure as a measurement of the compensated DUT's error: the reference's uncertainty and
    the reading's noise (the calibration's own uncertainty is what the figure measures, not an error of it).
    A root mean square is known to the root mean square of its terms' uncertainties (the triangle
    inequality); a largest value to its pose's; a drift to its two setpoints' zero-g offsets, whose pointing
    errors repeat (the same table angles) and cancel."""
    stderr_g = np.maximum(np.asarray(stderr_g, dtype=float), 0.0)
    pointing = np.diagonal(pointing_covariance_g2(reference_g, reference_u.accuracy_rad), axis1=1, axis2=2)
    axis_u = np.sqrt(stderr_g**2 + pointing + (reference_g * reference_u.gravity_relative_u) ** 2)
    direction = compensated_g / np.linalg.norm(compensated_g, axis=1, keepdims=True)
    norm_u = np.sqrt(np.sum((direction * stderr_g) ** 2, axis=1)
                     + (np.linalg.norm(reference_g, axis=1) * reference_u.gravity_relative_u) ** 2)
    error = np.abs(compensated_g - reference_g)
    worst_pose, worst_axis = np.unravel_index(np.argmax(error), error.shape)
    # A reading's noise turns pitch by noise / |g|, roll by noise / |g in the x–z plane| (judged only where
    # that is at least ROLL_DEFINED_G): the more sensitive of the two bounds it. A direction's error, by noise
    # over the vector's size.
    lever_g = np.linalg.norm(reference_g, axis=1)
    if angle == "tilt":
        lever_g = np.minimum(lever_g, np.maximum(np.hypot(reference_g[:, 0], reference_g[:, 2]), ROLL_DEFINED_G))
    tilt_u_rad = np.sqrt(reference_u.accuracy_rad**2 / 3.0 + (np.max(stderr_g, axis=1) / lever_g) ** 2)
    tilted = int(np.argmax(ANGLE_ERRORS[angle](compensated_g, reference_g)))
    offset_u = np.array([_offset_u_g(stderr_g[g], reference_g[g]) for g in groups])                   # (K, 3)
    high, low = np.argmax(offsets_mg, axis=0), np.argmin(offsets_mg, axis=0)
    drift_u = np.sqrt(offset_u[high, range(3)] ** 2 + offset_u[low, range(3)] ** 2)
    return {"coverage_factor": COVERAGE_FACTOR,
            f"rmse_{milli}": COVERAGE_FACTOR * 1e3 * float(np.sqrt(np.mean(norm_u**2))),
            f"max_axis_error_{milli}": COVERAGE_FACTOR * 1e3 * float(axis_u[worst_pose, worst_axis]),
            f"max_{angle}_error_deg": COVERAGE_FACTOR * float(np.degrees(tilt_u_rad[tilted])),
            f"drift_{milli}": (COVERAGE_FACTOR * 1e3 * drift_u).tolist()}


def _offset_u_g(stderr_g: np.ndarray, reference_g: np.ndarray) -> np.ndarray:
    """(3,) the standard uncertainty of zero_g_offset_mg's intercept (in g) from the poses' noise."""
    n = len(stderr_g)
    rms = np.sqrt(np.mean(stderr_g**2, axis=0))
    if n < 3:
        return rms / np.sqrt(n)
    spread = np.sum((reference_g - reference_g.mean(axis=0)) ** 2, axis=0)
    leverage = np.divide(reference_g.mean(axis=0) ** 2, spread, out=np.zeros(3), where=spread > 1e-12)
    return rms * np.sqrt(1.0 / n + leverage)


def zero_g_offset_mg(error_mg: np.ndarray, reference_g: np.ndarray) -> np.ndarray:
    """Each axis's error as a straight line in that axis's reference gravity: its value at zero g (the
    residual bias, whatever residual scale error the poses show). Fewer than three poses: the mean error."""
    if len(error_mg) < 3:
        return np.mean(error_mg, axis=0)
    g_mean = reference_g.mean(axis=0)
    e_mean = error_mg.mean(axis=0)
    spread = np.sum((reference_g - g_mean) ** 2, axis=0)
    slope = np.divide(np.sum((reference_g - g_mean) * (error_mg - e_mean), axis=0), spread,
                      out=np.zeros(3), where=spread > 1e-12)
    return e_mean - slope * g_mean


def tilt_errors_deg(compensated_g: np.ndarray, reference_g: np.ndarray) -> np.ndarray:
    """Per pose, the larger of the Eq. 10 pitch and roll errors (roll only where it is defined). The angles
    are of the acceleration of gravity, the negative of what a sensor at rest reads."""
    pitch, roll = tilt_angles_deg(-compensated_g)
    pitch_ref, roll_ref = tilt_angles_deg(-reference_g)
    roll_error = (roll - roll_ref + 180.0) % 360.0 - 180.0
    defined = np.hypot(reference_g[:, 0], reference_g[:, 2]) >= ROLL_DEFINED_G
    return np.maximum(np.abs(pitch - pitch_ref), np.where(defined, np.abs(roll_error), 0.0))


def direction_errors_deg(compensated: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Per pose, the angle between the compensated vector and its reference."""
    cosine = np.sum(compensated * reference, axis=1) / (np.linalg.norm(compensated, axis=1)
                                                        * np.linalg.norm(reference, axis=1))
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


#: A vector channel's angle figure: gravity's Eq. 10 tilt (pitch and roll), or any vector's direction.
AngleFigure = Literal["tilt", "direction"]
ANGLE_ERRORS: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] = {
    "tilt": tilt_errors_deg, "direction": direction_errors_deg}
