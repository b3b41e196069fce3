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
              reference_accuracy_rad: float = 0.0, gravity_g: float = 1.0,
              approach: np.ndarray | None = None,
              rate_c_per_min: np.ndarray | None = None) -> tuple[ThermalModel, np.ndarray, np.ndarray, float]:
    """Refine `start`'s coefficients of the `free` parameters against every pose; fixed ones keep theirs.
    With `approach` (its hysteresis state per pose: ±1 warming, cooling, or between them while it swings) each
    pose's reading also carries a bias of approach × h, and with `rate_c_per_min` one of rate × c, h and c per
    axis fitted with the rest (a hysteresis, which stays at rest, and what follows the rate of change, which does not): (the model,
    h in g, c in g per °C/min; zeros for a term not fitted) and the fit's χ² (its whitened residuals' sum of
    squares)."""
    x = start.scaled(temperature_c)
    powers = np.vander(x, start.coefficients.shape[1], increasing=True)  # (n, degree + 1)
    stderr_g = np.maximum(np.asarray(stderr_g, dtype=float), 1e-9)
    rows = np.flatnonzero(free)

    n_coefficients = len(rows) * start.coefficients.shape[1]
    terms = [np.asarray(v, dtype=float)[:, None] for v in (approach, rate_c_per_min) if v is not None]

    def model(theta: np.ndarray) -> np.ndarray:
        coefficients = start.coefficients.copy()
        coefficients[rows] = theta[:n_coefficients].reshape(len(rows), -1)
        return powers @ coefficients.T  # (n, 12) parameters at each pose's temperature

    def reading(theta: np.ndarray) -> np.ndarray:
        extra = theta[n_coefficients:].reshape(-1, 3)
        return mean_g - sum((term * extra[k] for k, term in enumerate(terms)), np.zeros_like(mean_g))

    if mode == "reference":
        assert reference_g is not None
        sigma_g = reference_sigma_g(stderr_g, reference_g, reference_accuracy_rad)

        def residuals(theta: np.ndarray) -> np.ndarray:
            return ((correct(reading(theta), model(theta)) - reference_g) / sigma_g).ravel()
    else:
        weights = norm_sigma(mean_g, stderr_g)

        def residuals(theta: np.ndarray) -> np.ndarray:
            return (np.linalg.norm(correct(reading(theta), model(theta)), axis=1) - gravity_g) / weights

    initial = np.concatenate([start.coefficients[rows].ravel(), np.zeros(3 * len(terms))])
    result = least_squares(residuals, initial, method="lm", xtol=1e-12, ftol=1e-12)
    coefficients = start.coefficients.copy()
    coefficients[rows] = result.x[:n_coefficients].reshape(len(rows), -1)
    refined = ThermalModel(start.domain_c, coefficients, np.empty((0, 12)), start.degree, list(start.warnings))
    extra = iter(result.x[n_coefficients:].reshape(-1, 3))
    fitted = [next(extra) if v is not None else np.zeros(3) for v in (approach, rate_c_per_min)]
    return refined, fitted[0], fitted[1], float(2.0 * result.cost)
