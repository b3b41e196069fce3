"""One fit of the gyroscope's whole thermal model: each of its 27 parameters a polynomial of temperature, every
record (rate step and pose) at its own sensor temperature — the ramp method's, as `fit/joint.py` is the
accelerometer's.

On a ramp a band's records do not share one temperature (a fixture lagging a moving chamber drifts a few
degrees while a band's rate steps turn), and the two-stage fit (Levenberg–Marquardt per band at the band's mean
temperature, then polynomials) would blur each parameter's drift within the band: an ICM-42688-P's bias moves
by some m°/s per °C, about its noise in one record. Here the polynomials' coefficients are the unknowns of one
Levenberg–Marquardt problem over all calibration records, started from the two-stage result, with the
per-band fit's residuals and weights; the Jacobian is the model's (`gyro_model.distort_jacobian`) times each
record's powers of temperature.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.thermal import ThermalModel


def fit_gyro_joint(start: ThermalModel, temperature_c: np.ndarray, mean_dps: np.ndarray, stderr_dps: np.ndarray,
                   reference_dps: np.ndarray, force_g: np.ndarray, stderr_floor_dps: float) -> ThermalModel:
    """`start`'s coefficients refined against every record at its own temperature: (N,) temperatures, (N, 3)
    readings with their standard errors, true rates and specific forces. The model's domain becomes the records'
    temperatures (a band's records reach beyond its mean: the polynomials are fitted where they are used)."""
    temperature_c = np.asarray(temperature_c, dtype=float)
    start = over_domain(start, (float(temperature_c.min()), float(temperature_c.max())))
    x = start.scaled(temperature_c)
    powers = np.vander(x, start.coefficients.shape[1], increasing=True)  # (N, degree + 1)
    sigma = np.maximum(np.asarray(stderr_dps, dtype=float), stderr_floor_dps)
    shape = start.coefficients.shape

    def parameters(theta: np.ndarray) -> np.ndarray:
        return powers @ theta.reshape(shape).T  # (N, 27) at each record's temperature

    def residuals(theta: np.ndarray) -> np.ndarray:
        return ((gyro_model.distort_rate(reference_dps, force_g, parameters(theta)) - mean_dps) / sigma).ravel()

    def derivatives(theta: np.ndarray) -> np.ndarray:
        model = gyro_model.distort_jacobian(reference_dps, force_g, parameters(theta))  # (N, 3, 27)
        chained = model[:, :, :, None] * powers[:, None, None, :] / sigma[:, :, None, None]
        return chained.reshape(3 * len(powers), -1)

    result = least_squares(residuals, start.coefficients.ravel(), jac=derivatives, method="lm",
                           xtol=1e-12, ftol=1e-12)
    return ThermalModel(start.domain_c, result.x.reshape(shape), np.empty((0, shape[0])), start.degree,
                        list(start.warnings))


def over_domain(model: ThermalModel, domain_c: tuple[float, float]) -> ThermalModel:
    """The same polynomials written over another domain (exact: a polynomial of degree d is fixed by d + 1 points)."""
    if domain_c == model.domain_c or domain_c[1] <= domain_c[0]:
        return model
    moved = ThermalModel(domain_c, model.coefficients, model.residuals, model.degree, list(model.warnings))
    temperatures = np.linspace(*domain_c, model.degree + 1)
    values = model.parameters_at(temperatures, "extrapolate")  # (d + 1, P)
    powers = np.vander(moved.scaled(temperatures), model.degree + 1, increasing=True)
    coefficients = np.linalg.solve(powers, values).T
    return ThermalModel(domain_c, coefficients, model.residuals, model.degree, list(model.warnings))
