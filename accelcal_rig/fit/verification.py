"""How good a calibration is, judged on poses: |g| RMSE (Eq. 9), each axis's error against the reference
gravity, Eq. 10 tilt errors, and the residual zero-g drift over temperature.

The same figures serve the verification poses (never fitted: the figures that count) and, beside them,
the calibration poses (in-sample: a fit with as many parameters as data can beat its own noise there).
Arrays in, a plain dict out.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from accelcal_rig.fit.metrics import noise_floor_mg, norm_rmse_mg, tilt_angles_deg

#: Roll (Eq. 10) is judged only where gravity has at least this much in the x–z plane, in g: near ±90° of
#: pitch roll is undefined and any error in it is meaningless.
ROLL_DEFINED_G = 0.5


def pose_figures(compensated_g: np.ndarray, reference_g: np.ndarray, stderr_g: np.ndarray, setpoint_c: np.ndarray,
                 temperature_c: np.ndarray, align: bool, gravity_g: float = 1.0) -> dict[str, Any]:
    """The figures of merit of compensated readings (N, 3) against the gravity each pose expects (N, 3).

    `align`: a norm-only fit fixes no rotation of the sensor frame, so its output is first turned by the one
    rotation that best aligns it with the references (per-axis and tilt errors are then those of a sensor
    mounted as the fit found it). `gravity_g`: the site's gravity in standard g, what |g| is judged against.
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
        "n_poses": int(len(g)), "rmse_mg": norm_rmse_mg(compensated_g[g], gravity_g),
        "max_axis_error_mg": float(np.max(np.abs(error_mg[g]))),
        "offset_mg": zero_g_offset_mg(error_mg[g], reference_g[g]).tolist(),
    } for g in groups]
    offsets = np.array([row["offset_mg"] for row in by_setpoint])
    return {
        "n_poses": int(len(compensated_g)),
        "rmse_mg": norm_rmse_mg(compensated_g, gravity_g),
        "noise_floor_mg": noise_floor_mg(compensated_g, stderr_g),
        "max_axis_error_mg": float(np.max(np.abs(error_mg))),
        "rms_axis_error_mg": np.sqrt(np.mean(error_mg**2, axis=0)).tolist(),
        "max_tilt_error_deg": float(np.max(tilt_errors_deg(compensated_g, reference_g))),
        "drift_mg": (offsets.max(axis=0) - offsets.min(axis=0)).tolist(),
        "frame": "best rotation onto the references (norm-only fits fix none)" if align else "fixture",
        "by_setpoint": by_setpoint,
    }


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
