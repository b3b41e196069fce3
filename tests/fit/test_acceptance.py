"""The verdict: every stated limit judged with its figure's uncertainty under the decision rule, every
failure a reason, and nothing passes unjudged."""

import numpy as np
import pytest
from pydantic import ValidationError

from accelcal_rig.config.acceptance import Acceptance, ParameterLimits
from accelcal_rig.fit.decision import DecisionRule, decide
from accelcal_rig.fit.parameter_uncertainty import ParameterUncertainty
from accelcal_rig.fit.sfem import IDENTITY_PARAMETERS
from accelcal_rig.fit.thermal import ThermalModel
from tests.fit.vector_poses import judge_accelerometer as judge

VERIFIED = {"verification": {"rmse_mg": 0.014, "max_axis_error_mg": 0.05, "max_tilt_error_deg": 0.004,
                             "drift_mg": [0.02, 0.08, 0.01], "by_setpoint": [{}, {}],
                             "expanded_u": {"rmse_mg": 0.01, "max_axis_error_mg": 0.03, "max_tilt_error_deg": 0.002,
                                            "drift_mg": [0.01, 0.015, 0.01]}}}


def constant(parameters: np.ndarray) -> ThermalModel:
    return ThermalModel((-40.0, 60.0), parameters[:, None].copy(), np.empty((0, 12)), 0)


BIASED = constant(np.concatenate([[0.012, -0.030, 0.001], IDENTITY_PARAMETERS[3:]]))


def known(thermal: ThermalModel, standard: float) -> ParameterUncertainty:
    """Every parameter known to `standard` (a constant polynomial's coefficient variance)."""
    return ParameterUncertainty(thermal, np.full((12, 1, 1), standard**2), np.zeros(12), np.zeros(12))


def test_within_every_limit_passes_and_states_each_figure_with_its_uncertainty() -> None:
    limits = Acceptance(max_verification_rmse_mg=0.05, max_drift_mg=0.1,
                        parameters=ParameterLimits(at_c=25, bias_mg=31))
    judged = judge(VERIFIED, BIASED, "reference", limits, parameter_u=known(BIASED, 0.0001))
    assert judged.verdict == "PASS"
    assert judged.reasons == ["verification |g| RMSE 0.014 ± 0.01 mg, limit ≤ 0.05 mg: pass",
                              "verification drift of y 0.08 ± 0.015 mg, limit ≤ 0.1 mg: pass",
                              "bias y at 25 °C -30 ± 0.2 mg, limit ±31 mg: pass"]
    assert "simple acceptance" in judged.rule and "states no rule" in judged.rule
    bias = [c for c in judged.checks if c.limit_key == "accel.parameters.bias_mg"]
    assert [round(c.value, 6) for c in bias] == [12, -30, 1] and all(c.signed for c in bias)


def test_each_limit_not_met_is_a_reason() -> None:
    limits = Acceptance(max_verification_rmse_mg=0.01, max_axis_error_mg=0.5, max_tilt_error_deg=0.001,
                        parameters=ParameterLimits(bias_mg=25))
    judged = judge(VERIFIED, BIASED, "reference", limits)
    assert judged.verdict == "FAIL"
    assert judged.reasons == ["verification |g| RMSE 0.014 ± 0.01 mg, limit ≤ 0.01 mg: fail",
                              "largest verification tilt error 0.004 ± 0.002 °, limit ≤ 0.001 °: fail",
                              "bias y at 25 °C -30 mg, limit ±25 mg: fail"]


@pytest.mark.parametrize(("value", "simple", "guarded"), [
    (0.5, "pass", "pass"), (0.95, "pass", "conditional pass"), (1.0, "pass", "conditional pass"),
    (1.05, "fail", "conditional fail"), (1.5, "fail", "fail"), (-0.95, "pass", "conditional pass")])
def test_guarded_acceptance_is_conditional_inside_the_guard_band_where_simple_acceptance_decides(
        value: float, simple: str, guarded: str) -> None:
    assert decide(value, 0.1, 1.0, DecisionRule("simple")) == simple
    assert decide(value, 0.1, 1.0, DecisionRule("guarded")) == guarded
    # A wider guard band moves the edges: 0.8 is beyond 1 − 2.5 × 0.1.
    assert decide(0.8, 0.1, 1.0, DecisionRule("guarded", 2.5)) == "conditional pass"


def test_a_bias_inside_the_guard_band_is_conditional_under_guarded_and_pass_under_simple() -> None:
    limits = {"parameters": ParameterLimits(at_c=25, bias_mg=30.2)}
    u = known(BIASED, 0.0002)              # U = 0.4 mg: |−30| lies inside 30.2 ± 0.4
    simple = judge(VERIFIED, BIASED, "reference", Acceptance(decision_rule="simple", **limits), parameter_u=u)
    guarded = judge(VERIFIED, BIASED, "reference", Acceptance(decision_rule="guarded", **limits), parameter_u=u)
    assert simple.verdict == "PASS" and "no rule" not in simple.rule
    assert guarded.verdict == "CONDITIONAL" and guarded.reasons == [
        "bias y at 25 °C -30 ± 0.4 mg, limit ±30.2 mg: conditional pass"]
    assert "guarded acceptance" in guarded.rule and "w = U" in guarded.rule
    # One failing limit beside a conditional one: FAIL, with the failing one as the reason.
    both = Acceptance(decision_rule="guarded", max_verification_rmse_mg=0.001, **limits)
    failed = judge(VERIFIED, BIASED, "reference", both, parameter_u=u)
    assert failed.verdict == "FAIL" and failed.reasons == ["verification |g| RMSE 0.014 ± 0.01 mg, limit ≤ 0.001 mg: fail"]


def test_a_guard_band_factor_needs_guarded_acceptance() -> None:
    with pytest.raises(ValidationError, match="guard_band_factor"):
        Acceptance(guard_band_factor=2.0)
    assert Acceptance(decision_rule="guarded", guard_band_factor=2.0).guard_band_factor == 2.0


def test_verification_limits_without_verification_poses_fail() -> None:
    judged = judge({}, BIASED, "reference", Acceptance(max_drift_mg=0.1, max_axis_error_mg=1))
    assert judged.verdict == "FAIL" and all("no verification poses" in r or "fewer than two" in r
                                            for r in judged.reasons)


def test_a_partial_campaign_fails_unless_allowed() -> None:
    partial = "partial campaign: 100 of 264 poses stored (state aborted)"
    assert judge(VERIFIED, BIASED, "reference", Acceptance(), partial).verdict == "FAIL"
    allowed = judge(VERIFIED, BIASED, "reference", Acceptance(allow_partial=True), partial)
    assert allowed.verdict == "NOT JUDGED"      # allowed, and no limit stated: nothing to conform to
    assert allowed.reasons == ["no acceptance limits stated", partial + " (acceptance.allow_partial)"]
    limited = Acceptance(allow_partial=True, parameters=ParameterLimits(bias_mg=1000))
    assert judge(VERIFIED, BIASED, "reference", limited, partial).verdict == "PASS"


def test_no_limits_no_verdict_and_norm_only_is_not_judged_on_misalignment() -> None:
    unjudged = judge(VERIFIED, BIASED, "reference", Acceptance())
    assert unjudged.verdict == "NOT JUDGED" and unjudged.reasons == ["no acceptance limits stated"]
    turned = constant(np.concatenate([IDENTITY_PARAMETERS[:9], [0.01, 0.0, 0.0]]))
    limits = Acceptance(parameters=ParameterLimits(misalignment_mrad=1))
    assert judge(VERIFIED, turned, "reference", limits).verdict == "FAIL"
    norm_only = judge(VERIFIED, turned, "norm-only", limits)
    assert norm_only.verdict == "NOT JUDGED"
    assert norm_only.reasons == ["misalignment not judged: a norm-only fit determines none"]
