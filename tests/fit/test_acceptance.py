"""The verdict: every stated limit judged, every failure a reason, and nothing passes unjudged."""

import numpy as np

from accelcal_rig.config.acceptance import Acceptance, ParameterLimits
from accelcal_rig.fit.acceptance import judge
from accelcal_rig.fit.sfem import IDENTITY_PARAMETERS
from accelcal_rig.fit.thermal import ThermalModel

VERIFIED = {"verification": {"rmse_mg": 0.014, "max_axis_error_mg": 0.05, "max_tilt_error_deg": 0.004,
                             "drift_mg": [0.02, 0.08, 0.01], "by_setpoint": [{}, {}]}}


def constant(parameters: np.ndarray) -> ThermalModel:
    return ThermalModel((-40.0, 60.0), parameters[:, None].copy(), np.empty((0, 12)), 0)


BIASED = constant(np.concatenate([[0.012, -0.030, 0.001], IDENTITY_PARAMETERS[3:]]))


def test_within_every_limit_passes_and_says_what_was_met() -> None:
    limits = Acceptance(max_verification_rmse_mg=0.05, max_drift_mg=0.1,
                        parameters=ParameterLimits(at_c=25, bias_mg=31))
    judged = judge(VERIFIED, BIASED, "reference", limits)
    assert judged.verdict == "PASS"
    assert judged.reasons == ["verification |g| RMSE 0.014 mg ≤ 0.05 mg", "verification drift of y 0.08 mg ≤ 0.1 mg",
                              "bias y at 25 °C 30 mg ≤ 31 mg"]


def test_each_limit_not_met_is_a_reason() -> None:
    limits = Acceptance(max_verification_rmse_mg=0.01, max_axis_error_mg=0.5, max_tilt_error_deg=0.001,
                        parameters=ParameterLimits(bias_mg=25))
    judged = judge(VERIFIED, BIASED, "reference", limits)
    assert judged.verdict == "FAIL"
    assert judged.reasons == ["verification |g| RMSE 0.014 mg > 0.01 mg", "largest verification tilt error 0.004 ° > 0.001 °",
                              "bias y at 25 °C 30 mg > 25 mg"]


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
    assert judge(VERIFIED, turned, "norm-only", limits).reasons == [
        "misalignment not judged: a norm-only fit determines none"]
