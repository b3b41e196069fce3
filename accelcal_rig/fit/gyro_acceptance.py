"""The verdict on a DUT's gyroscope against `acceptance.gyro`, as the accelerometer's (fit/acceptance.py):
verification limits judged on the rate steps and poses the fit never saw, parameter limits on the
calibration at the limits' temperature, each figure with its own expanded uncertainty under the procedure's
decision rule; NOT JUDGED without limits."""

from __future__ import annotations

from typing import Any

import numpy as np

from accelcal_rig.config.acceptance import Acceptance, GyroAcceptance
from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.acceptance import NOT_JUDGED, Judgement, _partial, rule_of, verdict_of
from accelcal_rig.fit.decision import DecisionRule, LimitCheck, check
from accelcal_rig.fit.parameter_uncertainty import ParameterUncertainty
from accelcal_rig.fit.thermal import ThermalModel
from accelcal_rig.fit.uncertainty import COVERAGE_FACTOR

NO_GYRO_LIMITS = "no gyroscope acceptance limits stated"


def judge_gyro(metrics: dict[str, Any], thermal: ThermalModel, acceptance: Acceptance, partial: str = "",
               parameter_u: ParameterUncertainty | None = None) -> Judgement:
    """`acceptance`: the procedure's (its `gyro` limits, decision rule and allow_partial)."""
    if acceptance.gyro is None and not partial:
        return Judgement(NOT_JUDGED, [NO_GYRO_LIMITS])
    limits = acceptance.gyro or GyroAcceptance()
    rule = rule_of(acceptance)
    checks: list[LimitCheck] = []
    missing: list[str] = []
    verification = metrics.get("verification")
    expanded = (verification or {}).get("expanded_u", {})
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
            missing.append(f"{label}: no verification records stored (limit {limit:g} {unit})")
        else:
            checks.append(check(f"gyro.{key}", f"gyro {label}", float(value), expanded.get(figure), limit, unit, rule))
    if limits.parameters is not None:
        checks += _parameter_checks(thermal, limits, rule, parameter_u)
    judgement = verdict_of(checks, rule, _partial(partial, acceptance.allow_partial), NO_GYRO_LIMITS)
    if missing:
        return Judgement("FAIL", missing + [r for r in judgement.reasons if judgement.verdict == "FAIL"],
                         judgement.checks, rule.statement())
    return judgement


def _parameter_checks(thermal: ThermalModel, limits: GyroAcceptance, rule: DecisionRule,
                      parameter_u: ParameterUncertainty | None) -> list[LimitCheck]:
    assert limits.parameters is not None
    p = limits.parameters
    at = thermal.parameters_at(p.at_c, "clamp")
    low, high = thermal.domain_c
    used_c = min(max(p.at_c, low), high)   # outside the DUTs' own range: its nearest edge, and said so
    where = f"{p.at_c:g} °C" if used_c == p.at_c else f"{used_c:.2f} °C (the calibrated range's edge nearest {p.at_c:g} °C)"
    u = COVERAGE_FACTOR * parameter_u.standard(p.at_c)[0] if parameter_u is not None else np.full(len(at), np.nan)
    crosses = [f"{gyro_model.AXES[i]}{gyro_model.AXES[j]}" for i, j in gyro_model.CROSS_TERMS]
    rows = [("bias_dps", "bias", p.bias_dps, at[gyro_model.BIAS], u[gyro_model.BIAS], "°/s", list(gyro_model.AXES)),
            ("scale_error_ppm", "scale error", p.scale_error_ppm, (at[gyro_model.SCALE] - 1.0) * 1e6,
             u[gyro_model.SCALE] * 1e6, "ppm", list(gyro_model.AXES)),
            ("cross_axis_mrad", "cross-axis", p.cross_axis_mrad, at[gyro_model.CROSS] * 1e3, u[gyro_model.CROSS] * 1e3,
             "mrad", crosses),
            ("gsens_dps_per_g", "g-sensitivity", p.gsens_dps_per_g, at[gyro_model.GSENS], u[gyro_model.GSENS], "°/s/g",
             [f"{a}{b}" for a in gyro_model.AXES for b in gyro_model.AXES])]
    checks = []
    for key, label, limit, values, expanded, unit, names in rows:
        if limit is None:
            continue
        checks += [check(f"gyro.parameters.{key}", f"gyro {label} {name} at {where}", float(v),
                         None if np.isnan(e) else float(e), limit, unit, rule, signed=True)
                   for name, v, e in zip(names, np.atleast_1d(values), np.atleast_1d(expanded))]
    return checks
