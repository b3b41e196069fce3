"""Tilt angles before and after calibration against the reference angles (paper §4.2, Eq. 10, Table 5).

Each pose's reference pitch and roll come from the gravity direction the turntable set for that DUT; the
measured ones from its mean reading, raw and compensated with a calibration at the DUT's own temperature.
Eq. 10 is written for the acceleration of gravity (level reads Z = −1 g); readings here are specific force
(+1 g up), so it is applied to their negative. SEOQ, the paper's "sensor error optimisation quantity", is
|before − after| relative to the largest reference angle, 30° (in %).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from accelcal_rig.fit.calibration import CalibrationRangeWarning, ChannelCalibration, apply
from accelcal_rig.fit.metrics import tilt_angles_deg
from accelcal_rig.store.read import VectorPoses

SEOQ_FULL_SCALE_DEG = 30.0


@dataclass(frozen=True)
class TiltRow:
    serial: str
    pose_number: int
    reference_deg: tuple[float, float]     # (pitch, roll)
    before_deg: tuple[float, float]
    after_deg: tuple[float, float]
    seoq_percent: tuple[float, float]


def pitch_roll_deg(readings_g: np.ndarray) -> np.ndarray:
    """(n, 2) pitch and roll of Eq. 10 from specific-force readings (n, 3)."""
    pitch, roll = tilt_angles_deg(-np.asarray(readings_g, dtype=float))
    return np.column_stack([pitch, roll])


def tilt_rows(poses: VectorPoses, pose_numbers: np.ndarray, calibration: ChannelCalibration) -> list[TiltRow]:
    reference = pitch_roll_deg(poses.reference)
    before = pitch_roll_deg(poses.mean)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)  # reported by the caller, once
        after = pitch_roll_deg(apply(calibration, poses.mean, poses.temperature_c))
    seoq = np.abs(before - after) / SEOQ_FULL_SCALE_DEG * 100.0
    return [TiltRow(poses.serial, int(n), tuple(r), tuple(b), tuple(a), tuple(q))  # type: ignore[arg-type]
            for n, r, b, a, q in zip(pose_numbers, reference, before, after, seoq)]


def worst_errors_deg(rows: list[TiltRow]) -> tuple[float, float]:
    """Largest |angle − reference| over pitch and roll, before and after calibration."""
    before = max(max(abs(b - r) for b, r in zip(row.before_deg, row.reference_deg)) for row in rows)
    after = max(max(abs(a - r) for a, r in zip(row.after_deg, row.reference_deg)) for row in rows)
    return before, after
