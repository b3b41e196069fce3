"""What a lab asks of its registry across calibrations: how a sensor drifted between recalibrations (ageing)
and how a lot of parts is distributed (yield, spread, outliers)."""

from __future__ import annotations

from typing import Any

import numpy as np

_SECONDS_PER_YEAR = 365.25 * 86400.0
#: The shortest span of calibrations a drift per year is stated from (`rig registry trend --min-span-days`):
#: calibrations minutes apart measure the noise of the two calibrations, not ageing.
MIN_SPAN_DAYS = 30.0
#: The reason of a PASS that no limits judged: not counted in a yield.
UNJUDGED = "no acceptance limits stated"
UNJUDGED_GYRO = "no gyroscope acceptance limits stated"
#: The verdicts judged against acceptance limits: a CONDITIONAL one (inside a guard band) is judged, and counts
#: in a yield as neither passed nor failed.
JUDGED = ("PASS", "FAIL", "CONDITIONAL")
#: A figure further than this from its lot's median, in robust z (0.6745 · deviation / MAD), is an outlier
#: (Iglewicz & Hoaglin, "How to Detect and Handle Outliers", 1993).
OUTLIER_Z = 3.5
#: Each channel's bias column and its unit: an accelerometer's in mg, a gyroscope's in °/s.
BIAS = {"accel": ("bias_mg", "mg"), "gyro": ("bias_dps", "dps")}
#: Each channel's figures in a lot's statistics: (column, per axis).
LOT_FIGURES = {"accel": (("bias_mg", True), ("scale_error_ppm", True), ("nonorthogonality_mrad", False)),
               "gyro": (("bias_dps", True), ("scale_error_ppm", True), ("verification_rmse_dps", False),
                        ("arw_deg_per_rthr", True), ("bias_instability_dph", True))}


def by_channel(rows: list[dict[str, Any]]) -> dict[str, list[dict[str, Any]]]:
    """Rows of every channel split by channel, `accel` first (their order kept)."""
    channels = sorted({r.get("channel") or "accel" for r in rows}, key=lambda c: (c != "accel", c))
    return {c: [r for r in rows if (r.get("channel") or "accel") == c] for c in channels}


def trend(rows: list[dict[str, Any]], channel: str = "accel", min_span_days: float = MIN_SPAN_DAYS) -> dict[str, Any]:
    """Bias and scale error at the reference temperature across one serial's calibrations of one channel,
    oldest first, and their drift per year: a weighted straight line through them (weights from the stated
    uncertainties; unweighted where a calibration states none), stated only when the calibrations span at least
    `min_span_days` (`drift_not_stated` says why not). An accelerometer's bias is in mg, a gyroscope's in °/s
    (`bias_dps`, its drift `bias_drift_dps_per_year`)."""
    bias, unit = BIAS.get(channel, BIAS["accel"])
    rows = sorted((r for r in rows if (r.get("channel") or "accel") == channel), key=lambda r: (r["calibrated_at"], r["id"]))
    points = [{"id": r["id"], "channel": channel, "calibrated_at": r["calibrated_at"].isoformat(), "verdict": r["verdict"],
               "reference_c": r["reference_c"], bias: r[bias], f"bias_uncertainty_{unit}": r[f"bias_uncertainty_{unit}"],
               "scale_error_ppm": r["scale_error_ppm"], "scale_uncertainty_ppm": r["scale_uncertainty_ppm"]}
              for r in rows]
    years = np.array([(r["calibrated_at"] - rows[0]["calibrated_at"]).total_seconds() / _SECONDS_PER_YEAR
                      for r in rows]) if rows else np.array([])
    span_days = float(years.max() - years.min()) * _SECONDS_PER_YEAR / 86400.0 if len(years) else 0.0
    withheld = _withheld(len(rows), span_days, min_span_days)
    return {"calibrations": points, "span_days": span_days, "min_span_days": min_span_days,
            "drift_not_stated": withheld,
            f"bias_drift_{unit}_per_year": None if withheld else _drift(years, rows, bias, f"bias_uncertainty_{unit}"),
            "scale_drift_ppm_per_year": None if withheld else _drift(years, rows, "scale_error_ppm",
                                                                     "scale_uncertainty_ppm")}


def _withheld(calibrations: int, span_days: float, min_span_days: float) -> str | None:
    """Why no drift per year is stated, or None when one may be."""
    if calibrations < 2 or span_days == 0.0:
        return "needs two calibrations at different times"
    if span_days < min_span_days:
        return f"the calibrations span {_span_text(span_days)}, under the {min_span_days:g} days a drift per year needs"
    return None


def _span_text(days: float) -> str:
    """`12 minutes`, `5.2 hours`, `3.5 days`."""
    if days < 1.0 / 24.0:
        return f"{days * 1440.0:.0f} minutes"
    if days < 1.0:
        return f"{days * 24.0:.1f} hours"
    return f"{days:.1f} days"


def _drift(years: np.ndarray, rows: list[dict[str, Any]], key: str,
           uncertainty_key: str) -> list[dict[str, float | None]] | None:
    """Per axis: slope ± its expanded uncertainty (k = 2; None where a calibration states none), or None with
    fewer than two distinct times."""
    usable = [i for i, r in enumerate(rows) if r[key] is not None]
    if len({float(years[i]) for i in usable}) < 2:
        return None
    x = years[usable]
    values = np.array([rows[i][key] for i in usable], dtype=float)                 # (n, 3)
    stated = [rows[i][uncertainty_key] for i in usable]
    sigma = (np.array(stated, dtype=float) / 2.0 if all(s is not None for s in stated)
             else np.ones_like(values))
    result = []
    for axis in range(3):
        w = 1.0 / np.maximum(sigma[:, axis], 1e-12) ** 2
        s, sx, sxx = w.sum(), (w * x).sum(), (w * x * x).sum()
        sy, sxy = (w * values[:, axis]).sum(), (w * x * values[:, axis]).sum()
        delta = s * sxx - sx * sx
        slope = (s * sxy - sx * sy) / delta
        result.append({"per_year": float(slope), "expanded_uncertainty": float(2.0 * np.sqrt(s / delta))
                       if all(v is not None for v in stated) else None})
    return result


def lot_statistics(rows: list[dict[str, Any]], channel: str = "accel") -> dict[str, Any]:
    """A part's lot, one channel of it: each serial's newest calibration; yield against the acceptance limits,
    the spread of its figures (an accelerometer's bias, scale error and non-orthogonality; a gyroscope's bias,
    scale error, verification RMS error and noise), and the serials whose figures stand out."""
    newest: dict[str, dict[str, Any]] = {}
    for row in sorted(rows, key=lambda r: (r["calibrated_at"], r["id"])):
        if (row.get("channel") or "accel") == channel:
            newest[row["serial"]] = row
    latest = list(newest.values())
    rows = [r for r in rows if (r.get("channel") or "accel") == channel]
    judged = [r for r in latest if r["verdict"] in JUDGED
              and list(r["verdict_reasons"]) not in ([UNJUDGED], [UNJUDGED_GYRO])]
    passed = sum(r["verdict"] == "PASS" for r in judged)
    conditional = sum(r["verdict"] == "CONDITIONAL" for r in judged)
    figures = {name: (_per_axis(latest, name) if per_axis else _scalar(latest, name))
               for name, per_axis in LOT_FIGURES.get(channel, LOT_FIGURES["accel"])}
    return {
        "sensors": len(latest), "calibrations": len(rows), "judged": len(judged), "passed": passed,
        "conditional": conditional, "failed": len(judged) - passed - conditional,
        "yield": passed / len(judged) if judged else None,
        "distributions": {name: [_summary(column) for column in columns] for name, columns in figures.items()},
        "outliers": _outliers(latest, figures),
    }


def _per_axis(rows: list[dict[str, Any]], key: str) -> list[np.ndarray]:
    values = np.array([r[key] for r in rows if r[key] is not None], dtype=float).reshape(-1, 3)
    return [values[:, axis] for axis in range(3)]


def _scalar(rows: list[dict[str, Any]], key: str) -> list[np.ndarray]:
    return [np.array([r[key] for r in rows if r[key] is not None], dtype=float)]


def _summary(values: np.ndarray) -> dict[str, float] | None:
    if values.size == 0:
        return None
    p5, median, p95 = np.percentile(values, [5, 50, 95])
    return {"n": int(values.size), "mean": float(values.mean()), "std": float(values.std(ddof=1)) if values.size > 1
            else 0.0, "min": float(values.min()), "p5": float(p5), "median": float(median), "p95": float(p95),
            "max": float(values.max())}


def _outliers(rows: list[dict[str, Any]], figures: dict[str, list[np.ndarray]]) -> list[dict[str, Any]]:
    """Each (serial, figure, axis) whose robust z exceeds OUTLIER_Z, largest first."""
    found = []
    for name, columns in figures.items():
        keyed = [r for r in rows if r[name] is not None]
        for axis, column in enumerate(columns):
            if column.size < 5:  # too few for a spread to mean anything
                continue
            median = np.median(column)
            mad = np.median(np.abs(column - median))
            if mad == 0.0:
                continue
            z = 0.6745 * (column - median) / mad
            for index in np.flatnonzero(np.abs(z) > OUTLIER_Z):
                found.append({"serial": keyed[index]["serial"], "id": keyed[index]["id"], "figure": name,
                              "axis": "xyz"[axis] if len(columns) == 3 else None,
                              "value": float(column[index]), "robust_z": float(z[index])})
    return sorted(found, key=lambda o: -abs(o["robust_z"]))
