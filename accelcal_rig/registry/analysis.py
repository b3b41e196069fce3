"""What a lab asks of its registry across calibrations: how a sensor drifted between recalibrations (ageing)
and how a lot of parts is distributed (yield, spread, outliers)."""

from __future__ import annotations

from typing import Any

import numpy as np

_SECONDS_PER_YEAR = 365.25 * 86400.0
#: The reason of a PASS that no limits judged: not counted in a yield.
UNJUDGED = "no acceptance limits stated"
#: A figure further than this from its lot's median, in robust z (0.6745 · deviation / MAD), is an outlier
#: (Iglewicz & Hoaglin, "How to Detect and Handle Outliers", 1993).
OUTLIER_Z = 3.5


def trend(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Bias and scale error at the reference temperature across one serial's calibrations, oldest first,
    and their drift per year: a weighted straight line through them (weights from the stated uncertainties;
    unweighted where a calibration states none)."""
    rows = sorted(rows, key=lambda r: (r["calibrated_at"], r["id"]))
    points = [{"id": r["id"], "calibrated_at": r["calibrated_at"].isoformat(), "verdict": r["verdict"],
               "reference_c": r["reference_c"], "bias_mg": r["bias_mg"], "bias_uncertainty_mg": r["bias_uncertainty_mg"],
               "scale_error_ppm": r["scale_error_ppm"], "scale_uncertainty_ppm": r["scale_uncertainty_ppm"]}
              for r in rows]
    years = np.array([(r["calibrated_at"] - rows[0]["calibrated_at"]).total_seconds() / _SECONDS_PER_YEAR
                      for r in rows]) if rows else np.array([])
    return {"calibrations": points,
            "bias_drift_mg_per_year": _drift(years, rows, "bias_mg", "bias_uncertainty_mg"),
            "scale_drift_ppm_per_year": _drift(years, rows, "scale_error_ppm", "scale_uncertainty_ppm")}


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


def lot_statistics(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """A part's lot: each serial's newest calibration; yield against the acceptance limits, the spread of
    bias, scale error and non-orthogonality, and the serials whose figures stand out."""
    newest: dict[str, dict[str, Any]] = {}
    for row in sorted(rows, key=lambda r: (r["calibrated_at"], r["id"])):
        newest[row["serial"]] = row
    latest = list(newest.values())
    judged = [r for r in latest if r["verdict"] in ("PASS", "FAIL") and list(r["verdict_reasons"]) != [UNJUDGED]]
    passed = sum(r["verdict"] == "PASS" for r in judged)
    figures = {"bias_mg": _per_axis(latest, "bias_mg"), "scale_error_ppm": _per_axis(latest, "scale_error_ppm"),
               "nonorthogonality_mrad": _scalar(latest, "nonorthogonality_mrad")}
    return {
        "sensors": len(latest), "calibrations": len(rows), "judged": len(judged), "passed": passed,
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
