"""The verdict on a DUT's gyroscope against `acceptance.gyro`, as the accelerometer's (fit/acceptance.py):
verification limits judged on the rate steps and poses the fit never saw, parameter limits on the
calibration at the limits' temperature, each figure with its own expanded uncertainty under the procedure's
decision rule; NOT JUDGED without limits."""

from __future__ import annotations

from typing import Any

from accelcal_rig.config.acceptance import Acceptance, GyroAcceptance
from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.acceptance import (
    NOT_JUDGED,
    Judgement,
    ParameterLimit,
    _partial,
    parameter_checks,
    rule_of,
    verdict_of,
)
from accelcal_rig.fit.decision import DecisionRule, LimitCheck, check
from accelcal_rig.fit.parameter_uncertainty import ParameterUncertainty
from accelcal_rig.fit.thermal import ThermalModel

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
    """The rate-table model's limits (fit/gyro_model.py's parameters)."""
    assert limits.parameters is not None
    p = limits.parameters
    axes = list(gyro_model.AXES)
    crosses = [f"{gyro_model.AXES[i]}{gyro_model.AXES[j]}" for i, j in gyro_model.CROSS_TERMS]
    rows: list[ParameterLimit] = [
        ("bias_dps", "bias", p.bias_dps, gyro_model.BIAS, 1.0, 0.0, "°/s", axes),
        ("scale_error_ppm", "scale error", p.scale_error_ppm, gyro_model.SCALE, 1e6, -1.0, "ppm", axes),
        ("cross_axis_mrad", "cross-axis", p.cross_axis_mrad, gyro_model.CROSS, 1e3, 0.0, "mrad", crosses),
        ("gsens_dps_per_g", "g-sensitivity", p.gsens_dps_per_g, gyro_model.GSENS, 1.0, 0.0, "°/s/g",
         [f"{a}{b}" for a in axes for b in axes])]
    return parameter_checks(thermal, p.at_c, parameter_u, rows, rule, prefix="gyro.")
