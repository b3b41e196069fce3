"""The verdict on one DUT's calibration: PASS when it meets every acceptance limit the procedure states,
FAIL with the reasons otherwise, NOT JUDGED when the procedure states none (no specification, no statement
of conformity: the results and their uncertainties are all there is to say).

Verification limits are judged on the verification poses only; parameter limits on the calibration at the
limits' temperature; a campaign that stopped before its last pose fails unless the procedure allows it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from pydantic import ValidationError

from accelcal_rig.config.acceptance import Acceptance
from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.yaml_lines import parse_yaml_text
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.thermal import ThermalModel

Verdict = Literal["PASS", "FAIL", "NOT JUDGED"]
#: The reason of a calibration that no limits judged.
NO_LIMITS = "no acceptance limits stated"
NOT_JUDGED: Verdict = "NOT JUDGED"


@dataclass(frozen=True)
class Judgement:
    verdict: Verdict
    #: FAIL: every limit not met; PASS: every limit met; NOT JUDGED: that none was stated. One line each.
    reasons: list[str]


def judge(metrics: dict[str, Any], thermal: ThermalModel, mode: str, limits: Acceptance,
          partial: str = "") -> Judgement:
    """Every stated limit against the fit's figures; `partial` says how the campaign fell short, if it did."""
    checks: list[tuple[bool, str]] = []
    verification = metrics.get("verification")
    figures = [("max_verification_rmse_mg", "verification |g| RMSE", "rmse_mg", "mg"),
               ("max_axis_error_mg", "largest verification axis error", "max_axis_error_mg", "mg"),
               ("max_tilt_error_deg", "largest verification tilt error", "max_tilt_error_deg", "°")]
    for key, label, figure, unit in figures:
        limit = getattr(limits, key)
        if limit is None:
            continue
        if verification is None:
            checks.append((False, f"{label}: no verification poses stored (limit {limit:g} {unit})"))
            continue
        checks.append(_within(label, float(verification[figure]), limit, unit))
    if limits.max_drift_mg is not None:
        if verification is None or len(verification["by_setpoint"]) < 2:
            checks.append((False, f"verification drift: fewer than two verification temperatures (limit "
                                  f"{limits.max_drift_mg:g} mg)"))
        else:
            drift = np.asarray(verification["drift_mg"])
            axis = int(np.argmax(drift))
            checks.append(_within(f"verification drift of {'xyz'[axis]}", float(drift[axis]), limits.max_drift_mg, "mg"))
    if limits.parameters is not None:
        checks.extend(_parameter_checks(thermal, mode, limits))
    judged_any = bool(checks)
    if partial:
        checks.append((limits.allow_partial, f"{partial}" + (" (acceptance.allow_partial)" if limits.allow_partial
                                                            else ": a partial campaign fails")))
    if not judged_any and all(ok for ok, _ in checks):  # no limit stated: no conformity to state
        return Judgement(NOT_JUDGED, [NO_LIMITS, *(text for _, text in checks)])
    failed = [text for ok, text in checks if not ok]
    return Judgement("FAIL", failed) if failed else Judgement("PASS", [text for _, text in checks])


def _within(label: str, value: float, limit: float, unit: str) -> tuple[bool, str]:
    ok = bool(value <= limit)
    return ok, f"{label} {value:.4g} {unit} {'≤' if ok else '>'} {limit:g} {unit}"


def _parameter_checks(thermal: ThermalModel, mode: str, limits: Acceptance) -> list[tuple[bool, str]]:
    assert limits.parameters is not None
    p = limits.parameters
    at = thermal.parameters_at(p.at_c, "clamp")
    rows = [("bias", p.bias_mg, np.abs(at[0:3]) * 1e3, "mg", "xyz"),
            ("scale error", p.scale_error_ppm, np.abs(at[3:6] - 1.0) * 1e6, "ppm", "xyz"),
            ("non-orthogonality", p.nonorthogonality_mrad, np.abs(at[6:9]) * 1e3, "mrad", ("yx", "zx", "zy"))]
    checks = []
    if mode == "reference":
        rows.append(("misalignment", p.misalignment_mrad, np.abs(at[9:12]) * 1e3, "mrad", "xyz"))
    elif p.misalignment_mrad is not None:
        checks.append((True, "misalignment not judged: a norm-only fit determines none"))
    for label, limit, values, unit, names in rows:
        if limit is None:
            continue
        worst = int(np.argmax(values))
        checks.append(_within(f"{label} {names[worst]} at {p.at_c:g} °C", float(values[worst]), limit, unit))
    return checks


def recorded_acceptance(procedure_yaml: str, where: str) -> Acceptance:
    """The acceptance limits of the procedure a campaign stored (none when it stated none)."""
    try:
        return Procedure.model_validate(parse_yaml_text(procedure_yaml, where)).acceptance
    except (ValidationError, ConfigError) as exc:
        raise ConfigError(f"{where}: its stored procedure no longer validates: {str(exc).splitlines()[0]}") from None
