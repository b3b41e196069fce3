"""Ageing drift and lot statistics from registry rows: a planted drift is found with its uncertainty, a
planted outlier is named, and the yield counts each sensor's newest calibration."""

from __future__ import annotations

from datetime import datetime, timedelta

import numpy as np
import pytest

from accelcal_rig.registry.analysis import lot_statistics, trend


def row(k: int, serial: str, days: float, bias: list[float], scale: list[float], verdict: str | None = "PASS",
        u_bias: list[float] | None = None, nonorth: float = 0.5) -> dict:
    def figure(label: str, unit: str, value: list[float], expanded: list[float] | None, trend: bool) -> dict:
        return {"label": label, "unit": unit, "axes": "xyz" if len(value) == 3 else "", "value": value,
                "expanded_u": expanded, "trend": trend, "lot": True}

    return {"id": k, "serial": serial, "channel": "accel", "calibrated_at": datetime(2025, 1, 1) + timedelta(days=days),
            "verdict": verdict, "verdict_reasons": ["within the procedure's acceptance limits"], "reference_c": 25.0,
            "figures": {"bias": figure("bias", "mg", bias, u_bias, True),
                        "scale_error": figure("scale error", "ppm", scale, [40.0, 40.0, 40.0], True),
                        "nonorthogonality": figure("non-orthogonality", "mrad", [nonorth], None, False)}}


def test_a_planted_drift_is_recovered_with_the_weighted_least_squares_uncertainty() -> None:
    years = np.array([0.0, 0.5, 1.0, 2.0])
    rows = [row(k, "S", 365.25 * t, [1.0 + 0.2 * t, -2.0, 0.3 * t], [100.0 - 50.0 * t, 0.0, 0.0],
                u_bias=[0.1, 0.1, 0.2]) for k, t in enumerate(years)]
    result = trend(rows, "accel")
    assert result["drift_per_year"]["bias"]["unit"] == "mg"
    drift = result["drift_per_year"]["bias"]["axes"]
    assert [d["per_year"] for d in drift] == pytest.approx([0.2, 0.0, 0.3], abs=1e-9)
    sigma = 0.1 / 2.0  # the stated uncertainty is expanded (k = 2)
    expected = 2.0 * sigma / np.sqrt(np.sum((years - years.mean()) ** 2))  # equal weights: the textbook formula
    assert drift[0]["expanded_uncertainty"] == pytest.approx(expected)
    assert result["drift_per_year"]["scale_error"]["axes"][0]["per_year"] == pytest.approx(-50.0)
    assert [p["calibrated_at"][:10] for p in result["calibrations"]] == ["2025-01-01", "2025-07-02", "2026-01-01",
                                                                          "2027-01-01"]


def test_a_calibration_without_stated_uncertainty_has_a_drift_but_no_uncertainty_in_valid_json() -> None:
    import json

    rows = [row(k, "S", 365.25 * k, [0.1 * k, 0.0, 0.0], [0.0, 0.0, 0.0], u_bias=None) for k in range(3)]
    drift = trend(rows, "accel")["drift_per_year"]["bias"]["axes"]
    assert drift[0]["per_year"] == pytest.approx(0.1) and drift[0]["expanded_uncertainty"] is None
    json.loads(json.dumps(trend(rows, "accel"), default=str), parse_constant=lambda c: pytest.fail(f"not JSON: {c}"))


def test_a_pass_no_limits_judged_is_not_in_the_yield() -> None:
    rows = [row(1, "A", 0, [0, 0, 0], [0, 0, 0]), row(2, "B", 0, [0, 0, 0], [0, 0, 0]) | {
        "verdict_reasons": ["no acceptance limits stated"]}]
    result = lot_statistics(rows, "accel")
    assert result["judged"] == 1 and result["passed"] == 1 and result["sensors"] == 2


def test_one_calibration_has_no_drift_to_state() -> None:
    assert trend([row(1, "S", 0, [1, 2, 3], [0, 0, 0])], "accel")["drift_per_year"]["bias"] is None


def test_lot_statistics_count_the_newest_calibration_of_each_sensor_and_name_the_outlier() -> None:
    rng = np.random.default_rng(0)
    rows = [row(k, f"L-{k:03d}", 10, list(rng.normal(0, 5, 3)), list(rng.normal(0, 1000, 3)),
                verdict="FAIL" if k < 3 else "PASS") for k in range(40)]
    rows.append(row(100, "L-000", 20, [1.0, 1.0, 1.0], [0.0, 0.0, 0.0], verdict="PASS"))  # recalibrated: now passes
    rows.append(row(101, "L-ODD", 10, [90.0, 0.0, 0.0], [0.0, 0.0, 0.0]))                  # a part far off the lot
    result = lot_statistics(rows, "accel")
    assert result["sensors"] == 41 and result["calibrations"] == 42
    assert result["judged"] == 41 and result["passed"] == 39 and result["yield"] == pytest.approx(39 / 41)
    assert result["distributions"]["bias"]["unit"] == "mg"
    bias_x = result["distributions"]["bias"]["axes"][0]
    assert bias_x["n"] == 41 and abs(bias_x["median"]) < 3.0
    flagged = {(o["serial"], o["figure"], o["axis"]) for o in result["outliers"]}
    assert ("L-ODD", "bias", "x") in flagged
    assert result["outliers"][0]["serial"] == "L-ODD"


@pytest.mark.parametrize("apart_days, said", [(12 / 1440, "12 minutes"), (5 / 24, "5.0 hours"), (29.5, "29.5 days")])
def test_calibrations_closer_than_the_minimum_span_state_no_drift_per_year(apart_days: float, said: str) -> None:
    rows = [row(1, "S", 0, [1.0, 2.0, 3.0], [0, 0, 0], u_bias=[0.1] * 3),
            row(2, "S", apart_days, [1.5, 2.0, 3.0], [10, 0, 0], u_bias=[0.1] * 3)]
    result = trend(rows, "accel")
    assert result["drift_per_year"] == {"bias": None, "scale_error": None}
    assert result["drift_not_stated"] == f"the calibrations span {said}, under the 30 days a drift per year needs"
    assert result["span_days"] == pytest.approx(apart_days)
    stated = trend(rows, "accel", min_span_days=apart_days)  # the same calibrations, a span the caller accepts
    assert stated["drift_not_stated"] is None
    assert stated["drift_per_year"]["bias"]["axes"][0]["per_year"] == pytest.approx(0.5 / (apart_days / 365.25))


def test_a_conditional_verdict_is_judged_and_neither_passed_nor_failed() -> None:
    verdicts = ["PASS", "PASS", "CONDITIONAL", "FAIL", None]
    rows = [row(k, f"S{k}", 0, [0, 0, 0], [0, 0, 0], verdict=v) for k, v in enumerate(verdicts)]
    result = lot_statistics(rows, "accel")
    judged = [v for v in verdicts if v is not None]
    assert (result["judged"], result["passed"], result["conditional"], result["failed"]) == (
        len(judged), judged.count("PASS"), judged.count("CONDITIONAL"), judged.count("FAIL"))
    assert result["yield"] == pytest.approx(judged.count("PASS") / len(judged))
