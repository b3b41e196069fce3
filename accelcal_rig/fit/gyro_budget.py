"""A gyroscope's uncertainty budget (GUM, first order): what each source costs a compensated rate, per axis, at
rest and at the largest calibrated rate about each axis, over the calibrated range; and in a dry run how often
the verification records' errors against the simulation truth fall inside the expanded uncertainty.

Sources: the fit (each setpoint's parameter covariance, carried through the thermal polynomials); the
thermal model (each parameter's scatter about its polynomial beyond its setpoints' 1σ; a joint fit's, its
records' scatter about it beyond their noise); the temperature (a
reading's temperature uncertainty times the parameters' slope); the table's rate accuracy (± uniform, a
common relative error of every rate); its position accuracy (± uniform per axis: the turning axis tilted
anew at each setpoint, a cross-axis error the polynomials average over the setpoints); the Earth's rate
where the rig config does not place it (± uniform, its size); the bias's wander between its measurement and
its use (the noise record's bias instability at its flicker floor). The thermal model's term is the scatter
beyond what scatters the setpoints and has a source here (pointing, the bias's wander): nothing counts
twice. A compensated reading's own noise is not in it: it is stated for the calibration, what averaging
cannot remove.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.stats import chi2

from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.thermal import OutOfRange, ThermalModel
from accelcal_rig.fit.uncertainty import COVERAGE_FACTOR

#: Temperatures the worst case is sought over.
BUDGET_TEMPERATURES = 41


def polynomial_weights(thermal: ThermalModel, setpoint_temperatures_c: np.ndarray, sigmas: np.ndarray,
                       temperature_c: np.ndarray) -> np.ndarray:
    """W (m, P, K): each parameter's polynomial at each temperature as a linear combination of its K setpoint
    estimates, the weighted least squares fit_thermal makes (weights 1/σ on the residuals)."""
    n = len(setpoint_temperatures_c)
    degree = min(thermal.degree, n - 1)
    vander = np.vander(thermal.scaled(setpoint_temperatures_c), degree + 1, increasing=True)         # (K, d)
    at = np.vander(np.atleast_1d(thermal.scaled(temperature_c)), degree + 1, increasing=True)      # (m, d)
    weights = np.empty((len(at), sigmas.shape[1], n))
    for p in range(sigmas.shape[1]):
        w = 1.0 / np.where(np.isfinite(sigmas[:, p]) & (sigmas[:, p] > 0), sigmas[:, p], 1.0) ** 2
        normal = vander.T @ (vander * w[:, None])
        weights[:, p, :] = at @ np.linalg.solve(normal, vander.T * w[None, :])
    return weights


def rate_jacobian(true_dps: np.ndarray, force_g: np.ndarray, params: np.ndarray) -> np.ndarray:
    """∂(compensated rate)/∂θ (m, 3, 27) at a true rate: −(∂raw/∂ω)⁻¹ ∂raw/∂θ, ∂raw/∂ω = diag(slope)·K."""
    k = gyro_model.sensitivity_matrix(params)
    u = np.einsum("mij,mj->mi", k, true_dps)
    slope = (1.0 + params[:, gyro_model.ASYMMETRY] * np.sign(u)
             + 3.0 * params[:, gyro_model.NONLINEARITY] * (u / gyro_model.NONLINEARITY_RATE_DPS) ** 2)
    by_rate = slope[:, :, None] * k
    return -np.linalg.solve(by_rate, gyro_model.distort_jacobian(true_dps, force_g, params))


def _slope_per_c(thermal: ThermalModel, temperature_c: np.ndarray) -> np.ndarray:
    """dθ/dT (m, 27) from the polynomials."""
    low, high = thermal.domain_c
    derivative = np.polynomial.polynomial.polyder(thermal.coefficients.T) / (0.5 * (high - low))
    x = np.clip(thermal.scaled(temperature_c), -1.0, 1.0)
    return np.moveaxis(np.polynomial.polynomial.polyval(x, derivative), 0, -1)


def between_setpoints_sigma(systematic: dict[str, Any]) -> np.ndarray:
    """(27,) what makes each parameter's estimates scatter from setpoint to setpoint besides their fits' 1σ, and
    has a source of its own in the budget: the table's pointing (each setpoint's moves tilt the axes anew) on
    the cross-axis terms, the bias's wander on the bias. The thermal model's term is the scatter beyond these,
    so nothing is counted twice."""
    sigma = np.zeros(gyro_model.N_PARAMETERS)
    sigma[gyro_model.CROSS] = systematic["cross"]
    sigma[gyro_model.BIAS] = np.asarray(systematic.get("bias_instability_dps", np.zeros(3)), dtype=float)
    return sigma


def thermal_model_variance(thermal: ThermalModel, sigmas: np.ndarray,
                           between: np.ndarray | None = None) -> np.ndarray:
    """(27,) each parameter's scatter about its polynomial beyond what its setpoints' 1σ (and `between`: what
    scatters them that the budget counts elsewhere) explain, where that scatter is evidently more (its χ²
    beyond the 99 % quantile, the rule the setpoint fits widen by: a scatter within it is noise, and counting
    its excess anyway would only ever add); zero where the polynomial interpolates (no degrees of freedom
    left: said by fit_thermal's warning)."""
    if between is not None:
        sigmas = np.sqrt(sigmas**2 + between**2)
    n = len(thermal.residuals)
    dof = n - (min(thermal.degree, n - 1) + 1)
    if dof <= 0:
        return np.zeros(thermal.residuals.shape[1])
    safe = np.where(np.isfinite(sigmas) & (sigmas > 0), sigmas, np.inf)
    evident = np.sum((thermal.residuals / safe) ** 2, axis=0) > chi2.ppf(0.99, dof)
    scatter = np.sum(thermal.residuals**2, axis=0) / dof
    return np.where(evident, np.maximum(scatter - np.mean(sigmas**2, axis=0), 0.0), 0.0)


def sources_dps(true_dps: np.ndarray, force_g: np.ndarray, temperature_c: np.ndarray, thermal: ThermalModel,
                setpoint_temperatures_c: np.ndarray, covariances: np.ndarray, sigmas: np.ndarray,
                temperature_u_c: float, systematic: dict[str, Any], out_of_range: OutOfRange = "clamp"
                ) -> dict[str, np.ndarray]:
    """Each source's standard uncertainty (m, 3) of the compensated rate at each (true rate, force, temperature)."""
    true_dps, force_g = np.atleast_2d(true_dps), np.atleast_2d(force_g)
    temperature_c = np.atleast_1d(np.asarray(temperature_c, dtype=float))
    params = thermal.parameters_at(temperature_c, out_of_range)
    jacobian = rate_jacobian(true_dps, force_g, params)
    weights = polynomial_weights(thermal, setpoint_temperatures_c, sigmas, temperature_c)                # (m, P, K)
    fit_cov = np.einsum("mpk,kpq,mqk->mpq", weights, covariances, weights)
    misfit = systematic.get("model_misfit_dps")
    # A joint fit's lack of fit is its records' own excess scatter (gyro_fit.joint_misfit_dps), not its per-band
    # estimates' scatter about the polynomials.
    thermal_var = (thermal_model_variance(thermal, sigmas, between_setpoints_sigma(systematic)) if misfit is None
                   else np.zeros(gyro_model.N_PARAMETERS))
    misfit_dps = np.zeros(3) if misfit is None else np.asarray(misfit, dtype=float)
    slope = _slope_per_c(thermal, temperature_c)
    magnitude = np.abs(true_dps)
    # Each setpoint's moves tilt the turning axis anew: its cross-axis estimates carry their own pointing
    # error, which the polynomials average as they average the setpoints.
    pointing = np.zeros(gyro_model.N_PARAMETERS)
    pointing[gyro_model.CROSS] = systematic["cross"] ** 2
    pointing_var = np.einsum("mpk,p->mp", weights**2, pointing)
    return {
        "fit": np.sqrt(np.einsum("mip,mpq,miq->mi", jacobian, fit_cov, jacobian)),
        "thermal model": np.sqrt(np.einsum("mip,p->mi", jacobian**2, thermal_var) + misfit_dps**2),
        "temperature": np.abs(np.einsum("mip,mp->mi", jacobian, slope)) * temperature_u_c,
        "table rate": magnitude * systematic["scale"],
        "table pointing": np.sqrt(np.einsum("mip,mp->mi", jacobian**2, pointing_var)),
        "earth rate": np.full_like(magnitude, systematic["earth_dps"]),
        "bias instability": np.broadcast_to(np.asarray(systematic.get("bias_instability_dps", np.zeros(3)), dtype=float),
                                            magnitude.shape).copy(),
    }


def combined(sources: dict[str, np.ndarray]) -> np.ndarray:
    return np.sqrt(sum(u**2 for u in sources.values()))


def gyro_budget(thermal: ThermalModel, setpoint_temperatures_c: np.ndarray, covariances: np.ndarray,
                sigmas: np.ndarray, temperature_u_c: float, systematic: dict[str, Any], largest_rate_dps: float,
                gravity_g: float = 1.0) -> dict[str, Any]:
    """The budget at rest and at ±`largest_rate_dps` about each axis, gravity along each of ±x, ±y, ±z, per
    axis in °/s: each source's worst over those and the calibrated range, the combined, and by temperature."""
    grid = np.unique(np.concatenate([setpoint_temperatures_c, np.linspace(*thermal.domain_c, BUDGET_TEMPERATURES)]))
    axes = np.vstack([np.eye(3), -np.eye(3)])
    cases = {"at_rest": np.zeros((1, 3)), "at_largest_rate": largest_rate_dps * axes}
    out: dict[str, Any] = {"coverage_factor": COVERAGE_FACTOR, "temperature_u_c": temperature_u_c,
                           "largest_rate_dps": largest_rate_dps,
                           "reading": "a compensated rate, its noise averaged away; the calibration's share only"}
    for name, rates in cases.items():
        combos = [(t, r, f) for t in grid for r in rates for f in gravity_g * axes]
        t = np.array([c[0] for c in combos])
        sources = sources_dps(np.array([c[1] for c in combos]), np.array([c[2] for c in combos]), t, thermal,
                              setpoint_temperatures_c, covariances, sigmas, temperature_u_c, systematic)
        standard = combined(sources)
        out[name] = {"sources_dps": {k: v.max(axis=0).tolist() for k, v in sources.items()},
                     "standard_dps": standard.max(axis=0).tolist(),
                     "expanded_dps": (COVERAGE_FACTOR * standard.max(axis=0)).tolist(),
                     "worst_at_c": t[np.argmax(standard, axis=0)].tolist()}
    return out


def truth_coverage(raw_dps: np.ndarray, force_g: np.ndarray, reference_dps: np.ndarray, temperature_c: np.ndarray,
                   truth_parameters: np.ndarray, thermal: ThermalModel, setpoint_temperatures_c: np.ndarray,
                   covariances: np.ndarray, sigmas: np.ndarray, temperature_u_c: float,
                   systematic: dict[str, Any], out_of_range: OutOfRange) -> float:
    """Dry runs: the share of the verification records' axis errors inside their expanded uncertainty. The error
    is what the calibration makes of each reading minus what the simulation's true model makes of it: the
    reading's noise is in both, the calibration's error (and the table's, which the fit took in) is not."""
    compensated = gyro_model.correct_rate(raw_dps, force_g, thermal.parameters_at(temperature_c, out_of_range))
    true = gyro_model.correct_rate(raw_dps, force_g, truth_parameters)
    sources = sources_dps(reference_dps, force_g, temperature_c, thermal, setpoint_temperatures_c, covariances,
                          sigmas, temperature_u_c, systematic, out_of_range)
    return float(np.mean(np.abs(compensated - true) <= COVERAGE_FACTOR * combined(sources)))
