"""One fit of the whole thermal model: each Eq. 1 parameter a polynomial of temperature, every pose at its
own sensor temperature (the ramp method).

When poses are taken while the temperature moves, a setpoint's poses no longer share one temperature and
the two-stage fit (LM per setpoint, then polynomials) would blur the drift within each group. Here the
polynomial coefficients themselves are the unknowns of one Levenberg–Marquardt problem over all poses,
started from the two-stage result; the residuals and their weights are those of the per-setpoint fit.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from accelcal_rig.fit.lm import FitMode, norm_sigma, reference_sigma_g
from accelcal_rig.fit.sfem import correct
from accelcal_rig.fit.thermal import ThermalModel


def fit_joint(start: ThermalModel, free: np.ndarray, temperature_c: np.ndarray, mean_g: np.ndarray,
              stderr_g: np.ndarray, reference_g: np.ndarray | None, mode: FitMode,
              reference_accuracy_rad: float = 0.0, gravity_g: float = 1.0) -> ThermalModel:
    """Refine `start`'s coefficients of the `free` parameters against every pose; fixed ones keep theirs."""
    x = start.scaled(temperature_c)
    powers = np.vander(x, start.coefficients.shape[1], increasing=True)  # (n, degree + 1)
    stderr_g = np.maximum(np.asarray(stderr_g, dtype=float), 1e-9)
    rows = np.flatnonzero(free)

    def model(theta: np.ndarray) -> np.ndarray:
        coefficients = start.coefficients.copy()
        coefficients[rows] = theta.reshape(len(rows), -1)
        return powers @ coefficients.T  # (n, 12) parameters at each pose's temperature

    if mode == "reference":
        assert reference_g is not None
        sigma_g = reference_sigma_g(stderr_g, reference_g, reference_accuracy_rad)

        def residuals(theta: np.ndarray) -> np.ndarray:
            return ((correct(mean_g, model(theta)) - reference_g) / sigma_g).ravel()
    else:
        weights = norm_sigma(mean_g, stderr_g)

        def residuals(theta: np.ndarray) -> np.ndarray:
            return (np.linalg.norm(correct(mean_g, model(theta)), axis=1) - gravity_g) / weights

    result = least_squares(residuals, start.coefficients[rows].ravel(), method="lm", xtol=1e-12, ftol=1e-12)
    coefficients = start.coefficients.copy()
    coefficients[rows] = result.x.reshape(len(rows), -1)
    refined = ThermalModel(start.domain_c, coefficients, np.empty((0, 12)), start.degree, list(start.warnings))
    return refined
