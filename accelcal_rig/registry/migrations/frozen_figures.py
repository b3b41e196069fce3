"""The figures migrations 0002 and 0004 computed from each stored fit for the columns they added (bias, scale
error and non-orthogonality at the reference temperature with their expanded uncertainties; the noise
figures), as they computed them: frozen history, read from the fit as stored (a plain dict of the calibration
file's entry of its channel, version 2), not from a model class that changes. Registry rows recorded since
take their figures from their channel's model (registry/figures.py)."""

from __future__ import annotations

from typing import Any

import numpy as np

#: Where the figures are taken: 25 °C, or the nearest calibrated temperature.
REFERENCE_C = 25.0
_NAMES = ("bias_x_g", "bias_y_g", "bias_z_g", "scale_x", "scale_y", "scale_z", "nonorth_yx_rad", "nonorth_zx_rad",
          "nonorth_zy_rad")


def reference_figures(calibration: dict[str, Any]) -> dict[str, Any]:
    """Figures of a stored sensor calibration (its `sensor` entry) at the reference temperature."""
    sensor = calibration["sensor"]
    low, high = sensor["validity_c"]
    reference = float(np.clip(REFERENCE_C, low, high))
    values = _parameters_at(sensor["polynomial"], reference)
    own = _parameter_expanded(sensor.get("metrics", {}), reference)
    if own is not None:   # each parameter's own expanded uncertainty there, as the fit stated it
        bias_u: list[float] | None = [1e3 * own[f"bias_{axis}_g"] for axis in "xyz"]
        scale_u: list[float] | None = [1e6 * own[f"scale_{axis}"] for axis in "xyz"]
    else:                 # a fit from before: the reading's budget and the nearest setpoint's 2σ
        expanded = sensor.get("metrics", {}).get("expanded_uncertainty_mg")
        bias_u = [float(u) for u in expanded] if expanded else None
        sigma = _nearest_setpoint_sigma(sensor.get("setpoints", []), reference)
        scale_sigma = [float(s) for axis in "xyz" if (s := sigma.get(f"scale_{axis}")) is not None]
        scale_u = [2e6 * s for s in scale_sigma] if len(scale_sigma) == 3 else None
    return {
        "reference_c": reference,
        "bias_mg": [1e3 * values[f"bias_{axis}_g"] for axis in "xyz"],
        "bias_uncertainty_mg": bias_u,
        "scale_error_ppm": [1e6 * (values[f"scale_{axis}"] - 1.0) for axis in "xyz"],
        "scale_uncertainty_ppm": scale_u,
        "nonorthogonality_mrad": 1e3 * max(abs(values[n]) for n in ("nonorth_yx_rad", "nonorth_zx_rad",
                                                                    "nonorth_zy_rad")),
    }


def _parameter_expanded(metrics: dict[str, Any], temperature_c: float) -> dict[str, float] | None:
    """Each parameter's expanded uncertainty (k = 2) at a temperature the fit stated it at, if it did."""
    table = metrics.get("parameter_uncertainty")
    if not isinstance(table, dict):
        return None
    temperatures = [float(t) for t in table.get("temperatures_c", [])]
    at = [i for i, t in enumerate(temperatures) if abs(t - temperature_c) < 1e-6]
    if not at:
        return None
    return {name: float(values[at[0]]) for name, values in table.get("expanded", {}).items()}


def _parameters_at(polynomial: dict[str, Any], temperature_c: float) -> dict[str, float]:
    d_low, d_high = polynomial["domain_c"]
    x = (temperature_c - 0.5 * (d_low + d_high)) / (0.5 * (d_high - d_low)) if d_high > d_low else 0.0
    return {name: float(np.polynomial.polynomial.polyval(x, polynomial["coefficients"][name])) for name in _NAMES}


def _nearest_setpoint_sigma(setpoints: list[dict[str, Any]], temperature_c: float) -> dict[str, float | None]:
    """The per-setpoint fit's standard errors nearest the reference temperature (the LM covariance there)."""
    if not setpoints:
        return {}
    nearest = min(setpoints, key=lambda s: abs(float(s["temperature_c"]) - temperature_c))
    return dict(nearest.get("sigma", {}))


def noise_figures(calibration: dict[str, Any]) -> dict[str, Any]:
    """The Allan figures of a stored calibration (the noise record nearest 25 °C), per axis, where it has them:
    an accelerometer's velocity random walk and bias instability, a gyroscope's angle random walk and bias
    instability; the other channel's are None."""
    allan = calibration["sensor"].get("metrics", {}).get("allan") or {}
    names = ("vrw_m_s_per_rthr", "bias_instability_ug", "arw_deg_per_rthr", "bias_instability_dph")
    return {name: ([float(e["value"]) for e in allan[name]] if isinstance(allan.get(name), list) else None)
            for name in names}
