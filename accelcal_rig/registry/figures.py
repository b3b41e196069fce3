"""What a registry row says of a calibration beyond its identity: bias, scale error and non-orthogonality at
the reference temperature, with their expanded uncertainties (k = 2), computed from the stored fit.

Migration 0002 fills these for calibrations recorded before it, so this reads the fit as stored (a plain
dict of the calibration file's sensor entry), not a model class that may change.
"""

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
    expanded = sensor.get("metrics", {}).get("expanded_uncertainty_mg")
    sigma = _nearest_setpoint_sigma(sensor.get("setpoints", []), reference)
    scale_sigma = [float(s) for axis in "xyz" if (s := sigma.get(f"scale_{axis}")) is not None]
    return {
        "reference_c": reference,
        "bias_mg": [1e3 * values[f"bias_{axis}_g"] for axis in "xyz"],
        "bias_uncertainty_mg": [float(u) for u in expanded] if expanded else None,
        "scale_error_ppm": [1e6 * (values[f"scale_{axis}"] - 1.0) for axis in "xyz"],
        "scale_uncertainty_ppm": [2e6 * s for s in scale_sigma] if len(scale_sigma) == 3 else None,
        "nonorthogonality_mrad": 1e3 * max(abs(values[n]) for n in ("nonorth_yx_rad", "nonorth_zx_rad",
                                                                    "nonorth_zy_rad")),
    }


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
