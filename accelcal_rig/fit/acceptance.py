"""The verdict on one DUT's calibration against the acceptance limits the procedure states, each figure with
its own expanded uncertainty under the procedure's decision rule (fit/decision.py): PASS when every limit
passes, CONDITIONAL when one lies inside its guard band (guarded acceptance) and none fails, FAIL with the
reasons otherwise; NOT JUDGED when the procedure states no limit (no specification, no statement of
conformity: the results and their uncertainties are all there is to say).

Every quantity is judged alike: the channel's model (fit/channel_model.py) names the verification figures a
limit may judge and its kinds of parameter. Verification limits are judged on the verification records only;
parameter limits on the calibration at the limits' temperature; a campaign that stopped before its last pose
fails unless the procedure allows it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from pydantic import ValidationError

from accelcal_rig.config.acceptance import Acceptance
from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.yaml_lines import parse_yaml_text
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.channel_model import ChannelFit, ChannelModel, ParameterGroup
from accelcal_rig.fit.decision import DecisionRule, LimitCheck, check, is_conditional, worst
from accelcal_rig.fit.parameter_uncertainty import ParameterUncertainty
from accelcal_rig.fit.thermal import ThermalModel
from accelcal_rig.fit.uncertainty import COVERAGE_FACTOR

Verdict = Literal["PASS", "FAIL", "CONDITIONAL", "NOT JUDGED"]
#: The reason of a calibration that no limits judged (and a gyroscope's, before limits were keyed by channel).
NO_LIMITS = "no acceptance limits stated"
UNJUDGED_REASONS = (NO_LIMITS, "no gyroscope acceptance limits stated")
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


def judge(model: ChannelModel, channel: str, fitted: ChannelFit, acceptance: Acceptance,
          partial: str = "") -> Judgement:
    """Every limit the procedure states on this channel (`acceptance.<channel>`) against its fit's figures, each
    with its own expanded uncertainty under the procedure's decision rule; `partial` says how the campaign fell
    short, if it did. The figures and parameters a limit names are the channel model's."""
    rule = rule_of(acceptance)
    limits = acceptance.channels.get(channel)
    checks: list[LimitCheck] = []
    missing: list[str] = []
    notes: list[str] = []
    if limits is not None:
        verification = fitted.figures.get("verification")
        checks, missing = _figure_checks(model, channel, limits.figure_limits(), verification, rule)
        if limits.parameters is not None:
            stated = limits.parameters.limits()
            _known_keys(model, channel, stated, parameters=True)
            groups, unjudged = model.judged_groups(fitted.calibration)
            checks += parameter_checks(fitted.thermal, limits.parameters.at_c, fitted.parameter_u, model,
                                       [g for g in groups if g.key in stated], stated, rule, channel)
            left_out = [g for g in model.parameter_groups if g not in groups]
            notes = [note for note, group in zip(unjudged, left_out) if group.key in stated]
    judgement = verdict_of(checks, rule, _partial(partial, acceptance.allow_partial), NO_LIMITS)
    if notes and not missing:
        reasons = notes if judgement.verdict == NOT_JUDGED and not partial else judgement.reasons + notes
        return Judgement(judgement.verdict, reasons, judgement.checks, judgement.rule)
    if missing:  # a limit with nothing to judge it on fails
        return Judgement("FAIL", missing + [r for r in judgement.reasons if judgement.verdict == "FAIL"],
                         judgement.checks, rule.statement())
    return judgement


def _figure_checks(model: ChannelModel, channel: str, stated: dict[str, float], verification: dict[str, Any] | None,
                   rule: DecisionRule) -> tuple[list[LimitCheck], list[str]]:
    """Each stated figure limit against the verification figure it names (each axis of a per-axis one); the
    limits with nothing to judge them on, each with why."""
    _known_keys(model, channel, stated)
    checks: list[LimitCheck] = []
    missing: list[str] = []
    expanded = (verification or {}).get("expanded_u", {})
    for spec in model.limits:
        limit = stated.get(spec.key)
        if limit is None:
            continue
        value = None if verification is None else verification.get(spec.figure)
        if value is None:
            missing.append(f"{spec.label}: {spec.missing} (limit {limit:g} {spec.unit})")
            continue
        if spec.needs_temperatures and len((verification or {}).get("by_setpoint", [])) < spec.needs_temperatures:
            missing.append(f"{spec.label}: fewer than {_COUNTS.get(spec.needs_temperatures, spec.needs_temperatures)} "
                           f"verification temperatures (limit {limit:g} {spec.unit})")
            continue
        key = f"{channel}.{spec.key}"
        if isinstance(value, list):
            uncertainty = expanded.get(spec.figure) or [None] * len(value)
            checks += [check(key, f"{spec.label} of {axis}", float(v), u, limit, spec.unit, rule)
                       for axis, v, u in zip("xyz", value, uncertainty)]
        else:
            checks.append(check(key, spec.label, float(value), expanded.get(spec.figure), limit, spec.unit, rule))
    return checks, missing


_COUNTS = {2: "two", 3: "three"}


def unknown_limit(model: ChannelModel, stated: Mapping[str, float], parameters: bool = False) -> str | None:
    """Why the first of the `stated` limits is not one the channel's model judges (a figure limit, or with
    `parameters` a kind of parameter); None when it judges them all."""
    known = sorted(group.key for group in model.parameter_groups) if parameters else sorted(s.key for s in model.limits)
    unknown = [key for key in stated if key not in known]
    if not unknown:
        return None
    what = "kind of parameter" if parameters else "figure limit"
    return f"{unknown[0]} is not a {what} of the {model.sensor} model (its: {', '.join(known) or 'none'})"


def _known_keys(model: ChannelModel, channel: str, stated: dict[str, float], parameters: bool = False) -> None:
    """A limit its channel's model does not know is the procedure's mistake (the run's preparation refuses it; a
    campaign stored before a model changed may still hold one)."""
    problem = unknown_limit(model, stated, parameters)
    if problem:
        where = f"acceptance.{channel}.parameters" if parameters else f"acceptance.{channel}"
        raise ConfigError(f"{where}: {problem}")


def _partial(partial: str, allowed: bool) -> tuple[bool, str] | None:
    if not partial:
        return None
    return allowed, partial + (" (acceptance.allow_partial)" if allowed else ": a partial campaign fails")


def parameter_checks(thermal: ThermalModel, at_c: float, parameter_u: ParameterUncertainty | None,
                     model: ChannelModel, groups: Sequence[ParameterGroup], stated: dict[str, float],
                     rule: DecisionRule, channel: str) -> list[LimitCheck]:
    """Every stated parameter limit of a channel's model against its parameters at `at_c`, each with its own
    expanded uncertainty there: (value + offset) × factor, signed. Outside the DUTs' own range the range's
    nearest edge is judged, and said so."""
    at = thermal.parameters_at(at_c, "clamp")
    low, high = thermal.domain_c
    used_c = min(max(at_c, low), high)
    where = f"{at_c:g} °C" if used_c == at_c else f"{used_c:.2f} °C (the calibrated range's edge nearest {at_c:g} °C)"
    u = COVERAGE_FACTOR * parameter_u.standard(at_c)[0] if parameter_u is not None else np.full(len(at), np.nan)
    checks = []
    for group in groups:
        index = [model.parameter_names.index(name) for name in group.names]
        values, expanded = (at[index] + group.offset) * group.factor, u[index] * group.factor
        checks += [check(f"{channel}.parameters.{group.key}", f"{group.label} {column} at {where}", float(v),
                         None if np.isnan(e) else float(e), stated[group.key], group.unit, rule, signed=True)
                   for column, v, e in zip(group.columns, values, expanded)]
    return checks


def recorded_acceptance(procedure_yaml: str, where: str) -> Acceptance:
    """The acceptance limits of the procedure a campaign stored (none when it stated none)."""
    try:
        return Procedure.model_validate(parse_yaml_text(procedure_yaml, where)).acceptance
    except (ValidationError, ConfigError) as exc:
        raise ConfigError(f"{where}: its stored procedure no longer validates: {str(exc).splitlines()[0]}") from None
