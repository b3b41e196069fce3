"""The verdict on a DUT's gyroscope: PASS when its calibration meets every limit of `acceptance.gyro`, FAIL
with the reasons otherwise, NOT JUDGED without limits. Verification limits are judged on the rate steps and poses the fit never saw,
parameter limits on the calibration at the limits' temperature, each value against its limit (simple
acceptance, as the accelerometer's)."""

from __future__ import annotations

from typing import Any

import numpy as np

from accelcal_rig.config.acceptance import GyroAcceptance
from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.acceptance import NOT_JUDGED, Judgement, _within
from accelcal_rig.fit.thermal import ThermalModel

NO_GYRO_LIMITS = "no gyroscope acceptance limits stated"


def judge_gyro(metrics: dict[str, Any], thermal: ThermalModel, limits: GyroAcceptance | None,
               partial: str = "", allow_partial: bool = False) -> Judgement:
    if limits is None and not partial:
        return Judgement(NOT_JUDGED, [NO_GYRO_LIMITS])
    limits = limits or GyroAcceptance()
    checks: list[tuple[bool, str]] = []
    verification = metrics.get("verification")
    figures = [("max_verification_rmse_dps", "verification rate RMS error", "rmse_dps", "°/s"),
               ("max_axis_error_dps", "largest verification rate axis error", "max_axis_error_dps", "°/s"),
               ("max_scale_error_ppm", "largest verification scale error", "scale_error_ppm", "ppm"),
               ("max_rest_error_dps", "verification error at rest", "rest_error_dps", "°/s")]
    for key, label, figure, unit in figures:
        limit = getattr(limits, key)
        if limit is None:
            continue
        value = None if verification is None else verification.get(figure)
        if value is None:
            checks.append((False, f"{label}: no verification records stored (limit {limit:g} {unit})"))
        else:
            checks.append(_within(label, float(value), limit, unit))
    if limits.parameters is not None:
        p = limits.parameters
        at = thermal.parameters_at(p.at_c, "clamp")
        crosses = [f"{gyro_model.AXES[i]}{gyro_model.AXES[j]}" for i, j in gyro_model.CROSS_TERMS]
        rows = [("bias", p.bias_dps, np.abs(at[gyro_model.BIAS]), "°/s", list(gyro_model.AXES)),
                ("scale error", p.scale_error_ppm, np.abs(at[gyro_model.SCALE] - 1.0) * 1e6, "ppm", list(gyro_model.AXES)),
                ("cross-axis", p.cross_axis_mrad, np.abs(at[gyro_model.CROSS]) * 1e3, "mrad", crosses),
                ("g-sensitivity", p.gsens_dps_per_g, np.abs(at[gyro_model.GSENS]), "°/s/g",
                 [f"{a}{b}" for a in gyro_model.AXES for b in gyro_model.AXES])]
        for label, limit, values, unit, names in rows:
            if limit is not None:
                worst = int(np.argmax(values))
                checks.append(_within(f"gyro {label} {names[worst]} at {p.at_c:g} °C", float(values[worst]), limit, unit))
    judged_any = bool(checks)
    if partial:
        checks.append((allow_partial, partial + (" (acceptance.allow_partial)" if allow_partial
                                                 else ": a partial campaign fails")))
    if not judged_any and all(ok for ok, _ in checks):
        return Judgement(NOT_JUDGED, [NO_GYRO_LIMITS, *(text for _, text in checks)])
    failed = [text for ok, text in checks if not ok]
    return Judgement("FAIL", failed) if failed else Judgement("PASS", [text for _, text in checks])
