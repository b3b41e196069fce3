"""The verdict on one DUT's calibration against the acceptance limits the procedure states, each figure with
its own expanded uncertainty under the procedure's decision rule (fit/decision.py): PASS when every limit
passes, CONDITIONAL when one lies inside its guard band (guarded acceptance) and none fails, FAIL with the
reasons otherwise; NOT JUDGED when the procedure states no limit (no specification, no statement of
conformity: the results and their uncertainties are all there is to say).

Verification limits are judged on the verification poses only; parameter limits on the calibration at the
limits' temperature; a campaign that stopped before its last pose fails unless the procedure allows it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from pydantic import ValidationError

from accelcal_rig.config.acceptance import Acceptance
from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.yaml_lines import parse_yaml_text
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.decision import DecisionRule, LimitCheck, check, is_conditional, worst
from accelcal_rig.fit.parameter_uncertainty import ParameterUncertainty
from accelcal_rig.fit.thermal import ThermalModel
from accelcal_rig.fit.uncertainty import COVERAGE_FACTOR

Verdict = Literal["PASS", "FAIL", "CONDITIONAL", "NOT JUDGED"]
#: The reason of a calibration that no limits judged.
NO_LIMITS = "no acceptance limits stated"
NOT_JUDGED: Verdict = "NOT JUDGED"


@dataclass(frozen=True)
class Judgement:
    verdict: Verdict
    #: FAIL: every limit not met; CONDITIONAL: every limit inside its guard band; PASS: every limit met;
    #: NOT JUDGED: that none was stated. One line each.
    reasons: list[str]
    #: every figure judged, with its uncertainty and outcome (what the certificate's decision table states)
    checks: list[LimitCheck] = field(default_factory=list)
    #: the decision rule as stated ("" when nothing was judged)
    rule: str = ""

    def plain(self) -> dict[str, Any]:
        """What a calibration file and `rig fit --json` keep of it beside the verdict and its reasons."""
        return {"decision_rule": self.rule, "limits": [c.plain() for c in self.checks]}


def combined_verdict(verdicts: Sequence[str | None]) -> Verdict:
    """A DUT's verdict from its sensors': FAIL when one fails; NOT JUDGED when one is not judged (no statement
    of conformity for the DUT); CONDITIONAL when one is; PASS when all pass."""
    if "FAIL" in verdicts:
        return "FAIL"
    if any(v in (None, NOT_JUDGED) for v in verdicts):
        return NOT_JUDGED
    return "CONDITIONAL" if "CONDITIONAL" in verdicts else "PASS"


def rule_of(limits: Acceptance) -> DecisionRule:
    return DecisionRule(limits.decision_rule or "simple", limits.guard_band_factor, limits.decision_rule is not None)


def verdict_of(checks: list[LimitCheck], rule: DecisionRule, partial: tuple[bool, str] | None,
               no_limits: str) -> Judgement:
    """The sensor's verdict from its limits' outcomes: any fail FAIL, any conditional CONDITIONAL, else PASS;
    a partial campaign fails unless allowed; no limit at all NOT JUDGED."""
    deciding = [worst([c for c in checks if c.limit_key == key]) for key in dict.fromkeys(c.limit_key for c in checks)]
    reasons = [c.text() for c in deciding]
    if partial is not None and not partial[0]:
        return Judgement("FAIL", [c.text() for c in deciding if c.outcome == "fail"] + [partial[1]], checks,
                         rule.statement() if checks else "")
    notes = [partial[1]] if partial is not None else []
    if not deciding:
        return Judgement(NOT_JUDGED, [no_limits, *notes])
    outcomes = {c.outcome for c in deciding}
    if "fail" in outcomes:
        return Judgement("FAIL", [c.text() for c in deciding if c.outcome == "fail"], checks, rule.statement())
    verdict: Verdict = "CONDITIONAL" if any(is_conditional(o) for o in outcomes) else "PASS"
    return Judgement(verdict, reasons + notes, checks, rule.statement())


def judge(metrics: dict[str, Any], thermal: ThermalModel, mode: str, limits: Acceptance, partial: str = "",
          parameter_u: ParameterUncertainty | None = None) -> Judgement:
    """Every stated limit against the fit's figures, each with its own expanded uncertainty under the
    procedure's decision rule; `partial` says how the campaign fell short, if it did."""
    rule = rule_of(limits)
    checks: list[LimitCheck] = []
    missing: list[str] = []
    verification = metrics.get("verification")
    expanded = (verification or {}).get("expanded_u", {})
    figures = [("max_verification_rmse_mg", "verification |g| RMSE", "rmse_mg", "mg"),
               ("max_axis_error_mg", "largest verification axis error", "max_axis_error_mg", "mg"),
               ("max_tilt_error_deg", "largest verification tilt error", "max_tilt_error_deg", "°")]
    for key, label, figure, unit in figures:
        limit = getattr(limits, key)
        if limit is None:
            continue
        if verification is None:
            missing.append(f"{label}: no verification poses stored (limit {limit:g} {unit})")
            continue
        checks.append(check(key, label, float(verification[figure]), expanded.get(figure), limit, unit, rule))
    if limits.max_drift_mg is not None:
        if verification is None or len(verification["by_setpoint"]) < 2:
            missing.append(f"verification drift: fewer than two verification temperatures (limit "
                           f"{limits.max_drift_mg:g} mg)")
        else:
            drift_u = expanded.get("drift_mg", [None] * 3)
            checks += [check("max_drift_mg", f"verification drift of {axis}", float(d), drift_u[a],
                             limits.max_drift_mg, "mg", rule) for a, (axis, d) in enumerate(zip("xyz", verification["drift_mg"]))]
    notes = []
    if limits.parameters is not None:
        checks.extend(_parameter_checks(thermal, mode, limits, rule, parameter_u))
        if mode != "reference" and limits.parameters.misalignment_mrad is not None:
            notes.append("misalignment not judged: a norm-only fit determines none")
    judgement = verdict_of(checks, rule, _partial(partial, limits.allow_partial), NO_LIMITS)
    if notes and not missing:
        reasons = notes if judgement.verdict == NOT_JUDGED and not partial else judgement.reasons + notes
        return Judgement(judgement.verdict, reasons, judgement.checks, judgement.rule)
    if missing:  # a limit with nothing to judge it on fails
        return Judgement("FAIL", missing + [r for r in judgement.reasons if judgement.verdict == "FAIL"],
                         judgement.checks, rule.statement())
    return judgement


def _partial(partial: str, allowed: bool) -> tuple[bool, str] | None:
    if not partial:
        return None
    return allowed, partial + (" (acceptance.allow_partial)" if allowed else ": a partial campaign fails")


#: One parameter limit: (procedure key, label, limit, the parameters it judges, unit factor, offset, unit, names).
ParameterLimit = tuple[str, str, "float | None", Any, float, float, str, Sequence[str]]


def parameter_checks(thermal: ThermalModel, at_c: float, parameter_u: ParameterUncertainty | None,
                     limits: list[ParameterLimit], rule: DecisionRule, prefix: str = "") -> list[LimitCheck]:
    """Every stated parameter limit of any channel's model against its parameters at `at_c`, each with its own
    expanded uncertainty there: (value + offset) × factor, signed. Outside the DUTs' own range the range's
    nearest edge is judged, and said so."""
    at = thermal.parameters_at(at_c, "clamp")
    low, high = thermal.domain_c
    used_c = min(max(at_c, low), high)
    where = f"{at_c:g} °C" if used_c == at_c else f"{used_c:.2f} °C (the calibrated range's edge nearest {at_c:g} °C)"
    u = COVERAGE_FACTOR * parameter_u.standard(at_c)[0] if parameter_u is not None else np.full(len(at), np.nan)
    checks = []
    for key, label, limit, index, factor, offset, unit, names in limits:
        if limit is None:
            continue
        values, expanded = (np.atleast_1d(at[index]) + offset) * factor, np.atleast_1d(u[index]) * factor
        checks += [check(f"{prefix}parameters.{key}", f"{prefix.rstrip('.') + ' ' if prefix else ''}{label} {name} at "
                         f"{where}", float(v), None if np.isnan(e) else float(e), limit, unit, rule, signed=True)
                   for name, v, e in zip(names, values, expanded)]
    return checks


def _parameter_checks(thermal: ThermalModel, mode: str, limits: Acceptance, rule: DecisionRule,
                      parameter_u: ParameterUncertainty | None) -> list[LimitCheck]:
    """Eq. 1's limits (misalignment only where a reference fit determines it)."""
    assert limits.parameters is not None
    p = limits.parameters
    rows: list[ParameterLimit] = [
        ("bias_mg", "bias", p.bias_mg, slice(0, 3), 1e3, 0.0, "mg", "xyz"),
        ("scale_error_ppm", "scale error", p.scale_error_ppm, slice(3, 6), 1e6, -1.0, "ppm", "xyz"),
        ("nonorthogonality_mrad", "non-orthogonality", p.nonorthogonality_mrad, slice(6, 9), 1e3, 0.0, "mrad",
         ("yx", "zx", "zy"))]
    if mode == "reference":
        rows.append(("misalignment_mrad", "misalignment", p.misalignment_mrad, slice(9, 12), 1e3, 0.0, "mrad", "xyz"))
    return parameter_checks(thermal, p.at_c, parameter_u, rows, rule)


def recorded_acceptance(procedure_yaml: str, where: str) -> Acceptance:
    """The acceptance limits of the procedure a campaign stored (none when it stated none)."""
    try:
        return Procedure.model_validate(parse_yaml_text(procedure_yaml, where)).acceptance
    except (ValidationError, ConfigError) as exc:
        raise ConfigError(f"{where}: its stored procedure no longer validates: {str(exc).splitlines()[0]}") from None
