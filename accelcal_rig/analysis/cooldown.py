"""Free cool-down validation (paper §4.3, Fig. 11): how much each axis's output moves per kelvin while
the sensor cools at one pose, before and after thermal compensation.

The temperature coefficient is the slope of a straight line through output against the DUT's own
temperature (µg/K), per axis; the paper reports 1346 → 37 µg/K. Compensation uses the calibration at each
record's temperature, clamped to its calibrated range as the calibration file says.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from accelcal_rig.fit.calibration import CalibrationRangeWarning, ChannelCalibration, apply
from accelcal_rig.fit.metrics import temperature_coefficient_ug_per_k
from accelcal_rig.store.read import VectorPoses


@dataclass(frozen=True)
class CooldownResult:
    serial: str
    t_s: np.ndarray                 # (n,) campaign clock of each record
    temperature_c: np.ndarray       # (n,) DUT's own temperature
    before_g: np.ndarray            # (n, 3) raw mean of each record
    after_g: np.ndarray             # (n, 3) compensated
    coefficient_before_ug_per_k: np.ndarray   # (3,)
    coefficient_after_ug_per_k: np.ndarray    # (3,)
    span_before_mg: np.ndarray      # (3,) max − min of the output over the cool-down
    span_after_mg: np.ndarray
    outside_range: int              # records outside the calibrated range (clamped or extrapolated)


def analyse_cooldown(poses: VectorPoses, calibration: ChannelCalibration) -> CooldownResult:
    low, high = calibration.validity_c
    outside = int(np.sum((poses.temperature_c < low) | (poses.temperature_c > high)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)  # counted in `outside_range`
        after = apply(calibration, poses.mean, poses.temperature_c)
    before = poses.mean
    return CooldownResult(
        poses.serial, poses.t_s, poses.temperature_c, before, after,
        temperature_coefficient_ug_per_k(before, poses.temperature_c),
        temperature_coefficient_ug_per_k(after, poses.temperature_c),
        np.ptp(before, axis=0) * 1e3, np.ptp(after, axis=0) * 1e3, outside)
