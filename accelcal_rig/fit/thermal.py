"""Each Eq. 1 parameter as a polynomial of the sensor's own temperature (paper §3.2, Eq. 8).

Least squares in the scaled variable x = (T − T_ref) / half_range, T_ref the middle of the calibrated
range (numpy's Polynomial.fit with that domain): raw T³ columns over −40…60 °C are badly conditioned.
Each temperature's point is weighted by its fit's 1σ.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.polynomial import Polynomial

OutOfRange = Literal["clamp", "extrapolate"]


@dataclass(frozen=True)
class ThermalModel:
    """`coefficients[k]` are parameter k's polynomial in x ∈ [−1, 1] over `domain_c`, increasing powers."""

    domain_c: tuple[float, float]
    coefficients: np.ndarray              # (P, degree + 1); fixed parameters hold their constant value
    residuals: np.ndarray                 # (n_temperatures, P) per-temperature estimate minus polynomial
    degree: int
    warnings: list[str] = field(default_factory=list)

    def scaled(self, temperature_c: np.ndarray | float) -> np.ndarray:
        low, high = self.domain_c
        return (np.asarray(temperature_c, dtype=float) - 0.5 * (low + high)) / (0.5 * (high - low))

    def parameters_at(self, temperature_c: np.ndarray | float, out_of_range: OutOfRange = "clamp") -> np.ndarray:
        """Parameters (..., P) at each temperature; outside the domain clamp to its edge or extrapolate."""
        x = self.scaled(temperature_c)
        if out_of_range == "clamp":
            x = np.clip(x, -1.0, 1.0)
        return np.moveaxis(np.polynomial.polynomial.polyval(x, self.coefficients.T), 0, -1)


def fit_thermal(temperature_c: np.ndarray, parameters: np.ndarray, sigma: np.ndarray, free: np.ndarray,
                degree: int) -> ThermalModel:
    """Fit each free parameter's per-temperature estimates (n, P) against temperature (n,): Eq. 1's twelve, or
    any other channel model's."""
    temperature_c = np.asarray(temperature_c, dtype=float)
    n = temperature_c.size
    warnings = []
    used_degree = min(degree, n - 1)
    if used_degree < degree:
        warnings.append(f"{n} temperatures cannot fix a degree-{degree} polynomial: degree {used_degree} used")
    if n == used_degree + 1 and n > 1:
        warnings.append(f"{n} temperatures for degree {used_degree}: the polynomial interpolates, with no check "
                        "left (drift after compensation is zero by construction)")
    domain = (float(temperature_c.min()), float(temperature_c.max()))
    if domain[1] - domain[0] < 1e-9:
        domain = (domain[0] - 0.5, domain[0] + 0.5)  # one temperature: a constant over a nominal 1 °C
    count = parameters.shape[1]
    coefficients = np.zeros((count, degree + 1))
    for k in range(count):
        if not free[k]:
            coefficients[k, 0] = parameters[0, k]
            continue
        weights = 1.0 / np.where(np.isfinite(sigma[:, k]) & (sigma[:, k] > 0), sigma[:, k], 1.0)
        polynomial = Polynomial.fit(temperature_c, parameters[:, k], used_degree, domain=list(domain), w=weights)
        coefficients[k, : used_degree + 1] = polynomial.coef
    model = ThermalModel(domain, coefficients, np.empty((0, count)), degree, warnings)
    residuals = parameters - model.parameters_at(temperature_c, "extrapolate")
    return ThermalModel(domain, coefficients, residuals, degree, warnings)
