"""Each calibration parameter's own standard uncertainty at a temperature: what a limit on it (a bias, a scale
error, a misalignment at 25 °C) is judged with, and what a certificate states beside the parameter.

A parameter's thermal polynomial p(T) = Σ cⱼ xʲ has the coefficients' covariance Q, so u²(p(T)) = vᵀQv with
v = (1, x, x², …); to it add what moves the parameter beside its fit: the thermal model's excess scatter (a
variance), and the references' systematic errors that scale it (the site's gravity for an accelerometer's
scale factors, the table's rate accuracy for a gyroscope's; the table's pointing for its cross-axis terms;
the Earth's rate where unplaced and the bias's wander for its bias). The temperature reading's own
uncertainty is not a term: a parameter is stated at a reading of the DUT's own sensor, what the
calibration is a function of.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.gyro_budget import between_setpoints_sigma, thermal_model_variance
from accelcal_rig.fit.thermal import ThermalModel
from accelcal_rig.fit.uncertainty import COVERAGE_FACTOR, CoefficientCovariance

#: Where a certificate states a calibration's parameters (clamped to the calibrated range).
REFERENCE_C = 25.0


def reference_c(validity_c: tuple[float, float]) -> float:
    """Where a certificate states a calibration's parameters: 25 °C, or the calibrated range's nearest end."""
    low, high = validity_c
    return float(np.clip(REFERENCE_C, low, high))


def expanded_at(metrics: dict[str, Any], name: str, temperature_c: float) -> float | None:
    """A parameter's expanded uncertainty (k = 2) at a temperature, from the fit's table (exact where the table
    has the temperature, between them interpolated); None for a file fitted before the table existed."""
    table = metrics.get("parameter_uncertainty")
    if not isinstance(table, dict) or name not in table.get("expanded", {}):
        return None
    return float(np.interp(temperature_c, table["temperatures_c"], table["expanded"][name]))


def nearest_setpoint_sigma(setpoints: list[Any], temperature_c: float) -> dict[str, float | None]:
    """The per-setpoint fit's 1σ nearest a temperature (a calibration fitted before each parameter's own
    uncertainty was stated has only these)."""
    if not setpoints:
        return {}
    nearest = min(setpoints, key=lambda s: abs(float(s.temperature_c) - temperature_c))
    return dict(nearest.sigma)


def certificate_temperatures(domain_c: tuple[float, float]) -> np.ndarray:
    """Where a certificate states the parameters: the calibrated range's ends and middle, and 25 °C (or the
    range's nearest end)."""
    low, high = domain_c
    return np.unique([low, 0.5 * (low + high), high, float(np.clip(REFERENCE_C, low, high))])


@dataclass(frozen=True)
class ParameterUncertainty:
    thermal: ThermalModel
    quadratic: np.ndarray            # (P, n, n) each parameter's coefficient covariance
    variance: np.ndarray             # (P,) added as it is (thermal model, systematic offsets)
    relative: np.ndarray             # (P,) 1σ relative to the parameter's value (a reference's scale error)

    def standard(self, temperature_c: np.ndarray | float) -> np.ndarray:
        """(m, P) standard uncertainties at each temperature (clamped to the calibrated range)."""
        temperature_c = np.atleast_1d(np.asarray(temperature_c, dtype=float))
        x = np.clip(self.thermal.scaled(temperature_c), -1.0, 1.0)
        powers = np.vander(x, self.quadratic.shape[1], increasing=True)                    # (m, n)
        fitted = np.einsum("mi,pij,mj->mp", powers, self.quadratic, powers)
        values = self.thermal.parameters_at(temperature_c, "clamp")
        return np.sqrt(np.maximum(fitted, 0.0) + self.variance + (values * self.relative) ** 2)

    def expanded_table(self, temperature_c: np.ndarray, names: list[str]) -> dict[str, Any]:
        """U (k = 2) per parameter at each temperature, in the parameters' own units, as a file keeps it."""
        expanded = COVERAGE_FACTOR * self.standard(temperature_c)
        return {"coverage_factor": COVERAGE_FACTOR, "temperatures_c": [float(t) for t in temperature_c],
                "expanded": {name: expanded[:, k].tolist() for k, name in enumerate(names)}}


def of_sensor(thermal: ThermalModel, covariance: CoefficientCovariance,
              gravity_relative_u: float) -> ParameterUncertainty:
    """An accelerometer's: the coefficients' covariance by source (noise, pointing, excess scatter), the
    thermal model's excess, the site's gravity on the scale factors (everything is relative to it)."""
    n = covariance.n_powers
    total = covariance.noise + covariance.pointing + covariance.excess
    count = thermal.coefficients.shape[0]
    quadratic = np.zeros((count, n, n))
    for j, k in enumerate(np.flatnonzero(covariance.free)):
        quadratic[k] = total[j * n:(j + 1) * n, j * n:(j + 1) * n]
    relative = np.zeros(count)
    relative[3:6] = gravity_relative_u
    return ParameterUncertainty(thermal, quadratic, covariance.model_variance.copy(), relative)


def of_gyro(thermal: ThermalModel, setpoint_temperatures_c: np.ndarray, covariances: np.ndarray, sigmas: np.ndarray,
            systematic: dict[str, Any]) -> ParameterUncertainty:
    """A gyroscope's: each setpoint's fit covariance and the table's pointing (anew at each setpoint) through
    the weighted polynomial fit (as gyro_budget carries them), the thermal model's excess, the Earth's rate
    the rig does not place and the bias's wander on the bias, the table's rate accuracy on the scale."""
    k_count = len(setpoint_temperatures_c)
    degree = min(thermal.degree, k_count - 1)
    vander = np.vander(thermal.scaled(setpoint_temperatures_c), degree + 1, increasing=True)         # (K, d)
    pointing = np.zeros(gyro_model.N_PARAMETERS)
    pointing[gyro_model.CROSS] = systematic["cross"] ** 2
    quadratic = np.zeros((gyro_model.N_PARAMETERS, degree + 1, degree + 1))
    for p in range(gyro_model.N_PARAMETERS):
        w = 1.0 / np.where(np.isfinite(sigmas[:, p]) & (sigmas[:, p] > 0), sigmas[:, p], 1.0) ** 2
        mapping = np.linalg.solve(vander.T @ (vander * w[:, None]), vander.T * w[None, :])         # (d, K)
        quadratic[p] = mapping @ np.diag(covariances[:, p, p] + pointing[p]) @ mapping.T
    variance = thermal_model_variance(thermal, sigmas, between_setpoints_sigma(systematic))
    bias = np.asarray(systematic.get("bias_instability_dps", np.zeros(3)), dtype=float)
    variance[gyro_model.BIAS] += systematic["earth_dps"] ** 2 + bias**2
    relative = np.zeros(gyro_model.N_PARAMETERS)
    relative[gyro_model.SCALE] = systematic["scale"]
    return ParameterUncertainty(thermal, quadratic, variance, relative)
