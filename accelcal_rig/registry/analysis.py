"""What a lab asks of its registry across calibrations: how a sensor drifted between recalibrations (ageing)
and how a lot of parts is distributed (yield, spread, outliers)."""

from __future__ import annotations

from typing import Any

import numpy as np

from accelcal_rig.fit.acceptance import UNJUDGED_REASONS

_SECONDS_PER_YEAR = 365.25 * 86400.0
#: The shortest span of calibrations a drift per year is stated from (`rig registry trend --min-span-days`):
#: calibrations minutes apart measure the noise of the two calibrations, not ageing.
MIN_SPAN_DAYS = 30.0
#: The verdicts judged against acceptance limits: a CONDITIONAL one (inside a guard band) is judged, and counts
#: in a yield as neither passed nor failed.
JUDGED = ("PASS", "FAIL", "CONDITIONAL")
#: A figure further than this from its lot's median, in robust z (0.6745 · deviation / MAD), is an outlier
#: (Iglewicz & Hoaglin, "How to Detect and Handle Outliers", 1993).
OUTLIER_Z = 3.5


def by_channel(rows: list[dict[str, Any]]) -> dict[str, list[dict[str, Any]]]:
    """Rows of every channel split by channel, by the channels' names (their order kept)."""
    return {c: [r for r in rows if r["channel"] == c] for c in sorted({r["channel"] for r in rows})}


def trend(rows: list[dict[str, Any]], channel: str, min_span_days: float = MIN_SPAN_DAYS) -> dict[str, Any]:
    """The figures a drift per year is stated of (each channel model's: bias and scale error, at the reference
    temperature) across one serial's calibrations of one channel, oldest first, and their drift per year: a
    weighted straight line through them (weights from the stated uncertainties; unweighted where a calibration
    states none), stated only when the calibrations span at least `min_span_days` (`drift_not_stated` says why
    not). Each figure in its own unit."""
    rows = sorted((r for r in rows if r["channel"] == channel), key=lambda r: (r["calibrated_at"], r["id"]))
    names = list(dict.fromkeys(name for r in rows for name, figure in r["figures"].items() if figure["trend"]))
    points = [{"id": r["id"], "channel": channel, "calibrated_at": r["calibrated_at"].isoformat(), "verdict": r["verdict"],
               "reference_c": r["reference_c"],
               "figures": {name: _figure(r, name) for name in names if name in r["figures"]}} for r in rows]
    years = np.array([(r["calibrated_at"] - rows[0]["calibrated_at"]).total_seconds() / _SECONDS_PER_YEAR
                      for r in rows]) if rows else np.array([])
    span_days = float(years.max() - years.min()) * _SECONDS_PER_YEAR / 86400.0 if len(years) else 0.0
    withheld = _withheld(len(rows), span_days, min_span_days)
    return {"calibrations": points, "span_days": span_days, "min_span_days": min_span_days,
            "drift_not_stated": withheld,
            "drift_per_year": {name: None if withheld else _drift(years, rows, name) for name in names}}


def _figure(row: dict[str, Any], name: str) -> dict[str, Any]:
    figure = row["figures"][name]
    return {"label": figure["label"], "unit": figure["unit"], "value": figure["value"], "expanded_u": figure["expanded_u"]}


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


def _drift(years: np.ndarray, rows: list[dict[str, Any]], name: str) -> dict[str, Any] | None:
    """Per axis: slope ± its expanded uncertainty (k = 2; None where a calibration states none), in the figure's
    unit per year; None with fewer than two distinct times."""
    usable = [i for i, r in enumerate(rows) if name in r["figures"]]
    if len({float(years[i]) for i in usable}) < 2:
        return None
    x = years[usable]
    figures = [rows[i]["figures"][name] for i in usable]
    values = np.array([f["value"] for f in figures], dtype=float)                 # (n, axes)
    stated = [f["expanded_u"] for f in figures]
    sigma = (np.array(stated, dtype=float) / 2.0 if all(s is not None for s in stated)
             else np.ones_like(values))
    result = []
    for axis in range(values.shape[1]):
        w = 1.0 / np.maximum(sigma[:, axis], 1e-12) ** 2
        s, sx, sxx = w.sum(), (w * x).sum(), (w * x * x).sum()
        sy, sxy = (w * values[:, axis]).sum(), (w * x * values[:, axis]).sum()
        delta = s * sxx - sx * sx
        slope = (s * sxy - sx * sy) / delta
        result.append({"per_year": float(slope), "expanded_uncertainty": float(2.0 * np.sqrt(s / delta))
                       if all(v is not None for v in stated) else None})
    return {"label": figures[-1]["label"], "unit": figures[-1]["unit"], "axes": result}


def lot_statistics(rows: list[dict[str, Any]], channel: str) -> dict[str, Any]:
    """A part's lot, one channel of it: each serial's newest calibration; yield against the acceptance limits,
    the spread of the figures its channel model marks for a lot (an accelerometer's bias, scale error and
    non-orthogonality; a gyroscope's bias, scale error, verification RMS error and noise), and the serials
    whose figures stand out."""
    newest: dict[str, dict[str, Any]] = {}
    for row in sorted(rows, key=lambda r: (r["calibrated_at"], r["id"])):
        if row["channel"] == channel:
            newest[row["serial"]] = row
    latest = list(newest.values())
    rows = [r for r in rows if r["channel"] == channel]
    judged = [r for r in latest if r["verdict"] in JUDGED and not unjudged(r["verdict_reasons"])]
    passed = sum(r["verdict"] == "PASS" for r in judged)
    conditional = sum(r["verdict"] == "CONDITIONAL" for r in judged)
    names = list(dict.fromkeys(name for r in latest for name, figure in r["figures"].items() if figure["lot"]))
    figures = {name: _columns(latest, name) for name in names}
    return {
        "sensors": len(latest), "calibrations": len(rows), "judged": len(judged), "passed": passed,
        "conditional": conditional, "failed": len(judged) - passed - conditional,
        "yield": passed / len(judged) if judged else None,
        "distributions": {name: {"label": _labelled(latest, name), "unit": _unit(latest, name),
                                 "axes": [_summary(column) for column in columns]}
                          for name, columns in figures.items()},
        "outliers": _outliers(latest, figures),
    }


def unjudged(reasons: list[str]) -> bool:
    """Whether a calibration's reasons say no limits judged it (recorded as a PASS before NOT JUDGED was)."""
    return len(reasons) == 1 and reasons[0] in UNJUDGED_REASONS


def _columns(rows: list[dict[str, Any]], name: str) -> list[np.ndarray]:
    values = [r["figures"][name]["value"] for r in rows if name in r["figures"]]
    width = max(len(v) for v in values)
    stacked = np.array([v for v in values if len(v) == width], dtype=float).reshape(-1, width)
    return [stacked[:, axis] for axis in range(width)]


def _labelled(rows: list[dict[str, Any]], name: str) -> str:
    return str(next(r["figures"][name]["label"] for r in rows if name in r["figures"]))


def _unit(rows: list[dict[str, Any]], name: str) -> str:
    return str(next(r["figures"][name]["unit"] for r in rows if name in r["figures"]))


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
        keyed = [r for r in rows if name in r["figures"] and len(r["figures"][name]["value"]) == len(columns)]
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
