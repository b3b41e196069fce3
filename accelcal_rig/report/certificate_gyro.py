"""The gyroscope's part of an IMU's certificate, and the noise figures of both its sensors: what the DUT's
`gyro` calibration holds (results at the reference temperature with their 1σ, its verification, its
uncertainty budget at rest and at the largest calibrated rate, how the Earth's rate was taken out, the gauge,
the verdict) and each channel's Allan figures from the campaign's still record, as HTML fragments."""

from __future__ import annotations

import html
from collections.abc import Sequence
from typing import Any

import numpy as np

from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.acceptance import combined_verdict
from accelcal_rig.fit.calibration import GyroCalibration, SensorCalibration
from accelcal_rig.fit.parameter_uncertainty import REFERENCE_C
from accelcal_rig.report.certificate_decision import expanded_at


def _e(value: object) -> str:
    return html.escape(str(value))


def _grid(header: list[str], rows: Sequence[Sequence[object]], text_columns: int = 1) -> str:
    def cell(tag: str, i: int, value: object) -> str:
        return f"<{tag}{' class=text' if i < text_columns else ''}>{_e(value)}</{tag}>"

    head = "".join(cell("th", i, h) for i, h in enumerate(header))
    body = "".join("<tr>" + "".join(cell("td", i, v) for i, v in enumerate(row)) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _rows(rows: list[tuple[str, object]]) -> str:
    return "<table>" + "".join(f"<tr><td class='key'>{_e(k)}</td><td class='text'>{_e(v)}</td></tr>"
                               for k, v in rows) + "</table>"


def reference_c(gyro: GyroCalibration) -> float:
    low, high = gyro.validity_c
    return float(np.clip(REFERENCE_C, low, high))


def _with_u(value: float, expanded: float | None, factor: float, spec: str) -> str:
    text = format(value * factor, spec)
    return text if expanded is None else f"{text} ± {format(abs(expanded) * factor, spec.lstrip('+'))}"


def gyro_results(gyro: GyroCalibration) -> str:
    """The model's parameters at the reference temperature, a row per kind and a column per gyro axis, each ± its
    expanded uncertainty there."""
    at = reference_c(gyro)
    values = dict(zip(gyro_model.PARAMETER_NAMES, gyro.parameters_at(at).tolist()))
    axes = gyro_model.AXES

    def row(label: str, names: list[str], factor: float, offset: float, spec: str) -> list[str]:
        return [label, *(_with_u(values[n] + offset, expanded_at(gyro.metrics, n, at), factor, spec) for n in names)]

    others = [[b for b in axes if b != a] for a in axes]
    rows = [row("bias (°/s)", [f"bias_{a}_dps" for a in axes], 1.0, 0.0, "+.4f"),
            row("scale error (ppm)", [f"scale_{a}" for a in axes], 1e6, -1.0, "+.0f"),
            row("asymmetry (ppm)", [f"asymmetry_{a}" for a in axes], 1e6, 0.0, "+.0f"),
            row("nonlinearity (ppm at 1000 °/s)", [f"nonlinearity_{a}" for a in axes], 1e6, 0.0, "+.0f"),
            *(row(f"cross-axis K {', '.join(a + o[k] for a, o in zip(axes, others))} (mrad)",
                  [f"cross_{a}{o[k]}_rad" for a, o in zip(axes, others)], 1e3, 0.0, "+.3f") for k in range(2)),
            *(row(f"g-sensitivity G {', '.join(a + b for a in axes)} (°/s/g)",
                  [f"gsens_{a}{b}_dps_per_g" for a in axes], 1.0, 0.0, "+.4f") for b in axes)]
    low, high = gyro.validity_c
    return (f"<p>Calibrated range {low:.2f} … {high:.2f} °C (the DUT's own temperature sensor), ±{gyro.range_dps:g} °/s. "
            "Parameters of the rate-table model ω<sub>raw</sub> = b + u + a⊙|u| + n⊙u⊙(u/1000 °/s)² + G·f, u = K·ω, "
            f"at {at:.2f} °C, each ± its expanded uncertainty (k = 2: the fit's through the polynomials, the table's "
            "rate and pointing accuracy, the Earth's rate where unplaced, the bias's wander); the full polynomials "
            "are in the calibration file.</p>"
            + _grid(["parameter", "gyro x", "gyro y", "gyro z"], rows))


def gyro_verification(gyro: GyroCalibration) -> str:
    v = gyro.metrics.get("verification")
    if not isinstance(v, dict):
        return ("<p><b>No verification rate steps:</b> the gyroscope's calibration was not checked on rates it was "
                "not fitted to.</p>")
    temperatures = ", ".join(f"{t:g}" for t in v.get("temperatures_c", []))

    expanded = v.get("expanded_u", {})

    def dps(key: str) -> str:
        u = f" ± {expanded[key]:.4f}" if key in expanded else ""
        return "—" if v.get(key) is None else f"{v[key]:.4f}{u} °/s"

    rms = dps("rmse_dps") + (f" (before calibration {v['rmse_before_dps']:.4f} °/s; their noise floor "
                             f"{v['noise_floor_dps']:.4f} °/s)" if v.get("rmse_before_dps") is not None
                             and v.get("noise_floor_dps") is not None else "")
    scale_u = f" ± {expanded['scale_error_ppm']:.0f}" if "scale_error_ppm" in expanded else ""
    scale = "—" if v.get("scale_error_ppm") is None else f"{v['scale_error_ppm']:.0f}{scale_u} ppm"
    return _rows([
        ("rate steps", f"{v.get('rate_steps', 0)} at {temperatures} °C"),
        ("RMS axis error", rms),
        ("largest axis error", dps("max_axis_error_dps")),
        ("largest scale error along the turning axis", scale),
        ("error at rest (RMS, verification poses)", dps("rest_error_dps")),
    ])


def gyro_uncertainty(gyro: GyroCalibration) -> str:
    budget = gyro.metrics["uncertainty_budget"]
    rest, turning = budget["at_rest"], budget["at_largest_rate"]
    rate = f"{float(budget['largest_rate_dps']):g}"

    def cells(values: list[float]) -> list[str]:
        return [f"{u:.5f}" for u in values]

    rows = [[name, *cells(rest["sources_dps"][name]), *cells(turning["sources_dps"][name])]
            for name in turning["sources_dps"]]
    rows.append(["combined standard uncertainty", *cells(rest["standard_dps"]), *cells(turning["standard_dps"])])
    rows.append([f"expanded uncertainty (k = {budget['coverage_factor']:g}, about 95 %)",
                 *cells(rest["expanded_dps"]), *cells(turning["expanded_dps"])])
    coverage = gyro.metrics.get("truth_coverage_k2")
    check = (f"<p class='note'>Checked against the simulation truth: {coverage * 100:.1f} % of the verification "
             "records' axis errors lie inside their expanded uncertainty.</p>" if coverage is not None else "")
    return (f"<p>For {_e(budget['reading'])}: each source's largest standard uncertainty over the calibrated range "
            f"and gravity along ±x, ±y, ±z, at rest and at ±{rate} °/s (the largest calibrated rate) about each axis; "
            "°/s per axis (GUM, sources uncorrelated).</p>"
            + _grid(["source", "rest x", "rest y", "rest z", f"{rate} °/s x", "y", "z"], rows) + check)


def gyro_statements(gyro: GyroCalibration) -> str:
    return (f"<p class='note'><b>Earth's rate:</b> {_e(gyro.earth_rate)}. <b>Gauge</b> (the frame of K): "
            f"{_e(gyro.gauge)}.</p>")


def _interval(entry: dict[str, Any], spec: str) -> str:
    return f"{format(entry['value'], spec)} [{format(entry['low'], spec)}, {format(entry['high'], spec)}]"


#: (channel label, metric key, its name, unit, format) of each noise row.
_NOISE_ROWS = (
    ("gyroscope", "arw_deg_per_rthr", "angle random walk", "°/√h", ".4f"),
    ("gyroscope", "bias_instability_dph", "bias instability", "°/h", ".2f"),
    ("accelerometer", "vrw_m_s_per_rthr", "velocity random walk", "m/s/√h", ".5f"),
    ("accelerometer", "bias_instability_ug", "bias instability", "µg", ".1f"),
)


def noise(sensor: SensorCalibration, gyro: GyroCalibration | None) -> str:
    """Both sensors' Allan figures per axis with their 68 % intervals, and the record they come from; "" when
    the campaign had no still record."""
    figures = {"accelerometer": sensor.metrics.get("allan"), "gyroscope": gyro.metrics.get("allan") if gyro else None}
    rows, records = [], []
    for label, key, name, unit, spec in _NOISE_ROWS:
        allan = figures[label]
        if isinstance(allan, dict) and isinstance(allan.get(key), list):
            rows.append([f"{label}: {name} ({unit})", *(_interval(e, spec) for e in allan[key])])
    for label, allan in figures.items():
        if isinstance(allan, dict) and "duration_s" in allan:
            records.append(f"{label}: {allan['samples']} samples over {allan['duration_s']:.1f} s at "
                           f"{allan['setpoint_c']:g} °C")
    if not rows:
        return ""
    return ("<p>Overlapping Allan deviation of a still record per axis (IEEE Std 952 practice): the random walk and "
            "the bias instability fitted to it, each [68 % interval]. Records: " + _e("; ".join(records)) + ".</p>"
            + _grid(["figure", "x", "y", "z"], rows))


def overall_verdict(sensor: SensorCalibration, gyro: GyroCalibration | None) -> str:
    """The DUT's verdict from its sensors' (combined_verdict)."""
    return combined_verdict([sensor.verdict] + ([gyro.verdict] if gyro is not None else []))
