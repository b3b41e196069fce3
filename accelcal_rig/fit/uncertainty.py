"""The uncertainty of a compensated reading (GUM): each source's standard uncertainty per axis, combined in
quadrature and expanded with k = 2.

Sources:
- `reading_noise`: the reading's own sample noise (its standard error per axis, through the compensation);
- `calibration_noise`: the calibration poses' sample noise, through the fitted coefficients;
- `turntable_pointing`: the table's pointing accuracy, through the fitted coefficients (reference mode);
- `scatter_beyond_noise`: residual scatter the first two do not explain (the fit's χ²_red, when it is
  significantly above 1 at the 99 % level), through the coefficients;
- `thermal_model`: what Eq. 1 × a polynomial in temperature does not describe: the per-setpoint
  estimates' scatter about the polynomial beyond their own 1σ (when significant at the 95 % level), at
  each setpoint its own, interpolated between them; for a joint fit, each band's poses' common offset
  about the model, as a bias (budget.band_misfit);
- `hysteresis`: a reading at rest lies on one of its two branches, ±h from the calibration (the mean of
  both), h measured by a bidirectional ramp's joint fit (budget.hysteresis_u_g); absent where no fit
  measured it (a method that approaches each temperature from one side cannot: budget.not_included);
- `temperature`: the uncertainty of the temperature the reading is compensated at;
- `gravity`: the site's gravity value (every output is relative to it).

The coefficients' covariance is the sandwich G·Σ·Gᵀ of the linearised estimator, G the map from every
calibration pose's whitened residuals to the thermal model's coefficients: (JᵀJ)⁻¹Jᵀ for the joint fit;
for the two-stage fit, each setpoint's LM map followed by the weighted polynomial fit of each parameter
(two_stage_map) — the estimator actually used, not an idealised one. The noise and the pointing
covariances of each pose propagate separately, so the budget can say what each costs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.stats import chi2

from accelcal_rig.fit.lm import pointing_covariance_g2, reference_sigma_g
from accelcal_rig.fit.sfem import correct, correct_jacobian, error_matrix
from accelcal_rig.fit.thermal import OutOfRange, ThermalModel

COVERAGE_FACTOR = 2.0
#: Step of the numerical derivative of the compensation by temperature, °C.
_STEP_C = 1e-3


@dataclass(frozen=True)
class CoefficientCovariance:
    """Covariances of the free coefficients, flattened parameter-major (parameter, then power)."""

    free: np.ndarray                  # (12,) bool: the parameters the fit determined
    n_powers: int
    noise: np.ndarray                 # (P, P) from the calibration poses' sample noise
    pointing: np.ndarray              # (P, P) from the turntable's pointing accuracy
    excess: np.ndarray                # (P, P) from scatter beyond both (zero unless significant)
    model_variance: np.ndarray        # (12,) the thermal model's excess variance per parameter (zero if none)
    #: (3,) per axis, the standard uncertainty of a reading's hysteresis in g, as a bias of the raw reading,
    #: where the fit measured it (a bidirectional ramp's joint fit: budget.hysteresis_u_g); None: not measured
    hysteresis: np.ndarray | None = None
    #: (K,) and (K, 12): the thermal model's excess variance at each setpoint (model_variance), where the
    #: calibration measured it; empty: `model_variance` over the whole range
    model_temperatures_c: np.ndarray = field(default_factory=lambda: np.zeros(0))
    model_variance_by_temperature: np.ndarray = field(default_factory=lambda: np.zeros((0, 12)))

    def model_variance_at(self, temperature_c: np.ndarray) -> np.ndarray:
        """(n, 12) the thermal model's excess variance at each temperature: linear between the setpoints
        it was measured at, the nearest one's beyond them; `model_variance` where none are known."""
        temperature_c = np.atleast_1d(np.asarray(temperature_c, dtype=float))
        if not len(self.model_temperatures_c):
            return np.broadcast_to(self.model_variance, (len(temperature_c), 12))
        order = np.argsort(self.model_temperatures_c, kind="stable")
        known, variance = self.model_temperatures_c[order], self.model_variance_by_temperature[order]
        return np.stack([np.interp(temperature_c, known, variance[:, k]) for k in range(12)], axis=1)


def joint_map(jacobian: np.ndarray) -> np.ndarray:
    """(JᵀJ)⁻¹Jᵀ: how the whitened residuals move a least-squares fit's coefficients."""
    q, r = np.linalg.qr(jacobian)
    return np.linalg.solve(r, q.T)


def two_stage_map(setpoint_jacobians: list[np.ndarray], scaled_temperatures: np.ndarray, setpoint_sigma: np.ndarray,
                  free: np.ndarray, n_powers: int) -> np.ndarray:
    """How every pose's whitened residuals move the two-stage fit's coefficients: each setpoint's LM map to
    its parameters, then each parameter's polynomial, weighted by the setpoints' 1σ (fit_thermal)."""
    per_setpoint = [joint_map(j) for j in setpoint_jacobians]          # (p, R_j) each
    columns = np.cumsum([0] + [m.shape[1] for m in per_setpoint])
    powers = np.vander(scaled_temperatures, n_powers, increasing=True)  # (K, m)
    rows = np.flatnonzero(free)
    mapping = np.zeros((len(rows) * n_powers, columns[-1]))
    for p, k in enumerate(rows):
        weights = 1.0 / setpoint_sigma[:, k] ** 2
        fit = np.linalg.solve(powers.T @ (weights[:, None] * powers), powers.T * weights)   # (m, K)
        for j, setpoint_map in enumerate(per_setpoint):
            mapping[p * n_powers:(p + 1) * n_powers, columns[j]:columns[j + 1]] = np.outer(fit[:, j], setpoint_map[p])
    return mapping


def coefficient_covariance(mapping: np.ndarray, reference_g: np.ndarray | None, stderr_g: np.ndarray,
                           accuracy_rad: float, free: np.ndarray, n_powers: int, residuals: np.ndarray,
                           thermal_residuals: np.ndarray, setpoint_sigma: np.ndarray,
                           setpoint_temperatures_c: np.ndarray | None = None) -> CoefficientCovariance:
    """`mapping` (P, R): from every calibration pose's whitened residuals (pose by pose, as the fit weighs
    them) to the coefficients; `residuals`: those residuals at the solution (for χ²); `thermal_residuals`
    (K, 12) and `setpoint_sigma` (K, 12): the per-setpoint estimates about the polynomial and their 1σ, at
    `setpoint_temperatures_c` (K,) (without them the thermal model's term is one figure for the whole
    range). Rows of `mapping` beyond the coefficients are other quantities the same fit estimated
    (budget.calibration_covariance: a joint fit's hysteresis and rate terms): their covariances come out
    alongside, in the same matrices."""
    a = mapping
    n_poses = len(stderr_g)
    if reference_g is None:                                             # norm-only: |g| residuals, noise only
        noise, pointing = a @ a.T, np.zeros((a.shape[0], a.shape[0]))
    else:
        stderr_g = np.maximum(np.asarray(stderr_g, dtype=float), 1e-9)
        reference_g = np.asarray(reference_g, dtype=float)
        sigma = reference_sigma_g(stderr_g, reference_g, accuracy_rad)
        blocks = a.reshape(a.shape[0], n_poses, 3) / sigma[None]       # A_i S_i⁻¹, pose by pose
        flat = blocks.reshape(a.shape[0], 3 * n_poses)                          # sums over poses and axes as products
        noise = (blocks * stderr_g**2).reshape(a.shape[0], 3 * n_poses) @ flat.T
        turn = pointing_covariance_g2(reference_g, accuracy_rad)
        pointing = np.einsum("pna,nab->pnb", blocks, turn).reshape(a.shape[0], 3 * n_poses) @ flat.T
    dof = len(residuals) - a.shape[0]
    chi2_total = float(residuals @ residuals)
    excess = np.zeros_like(noise)
    if dof > 0 and chi2_total > chi2.ppf(0.99, dof):
        excess = (chi2_total / dof - 1.0) * (a @ a.T)
    if setpoint_temperatures_c is None or len(thermal_residuals) <= n_powers:
        variance, local = model_variance(thermal_residuals, setpoint_sigma, free, n_powers)
        return CoefficientCovariance(free, n_powers, noise, pointing, excess, variance)
    variance, local = model_variance(thermal_residuals, setpoint_sigma, free, n_powers,
                                     residual_sigma(setpoint_temperatures_c, setpoint_sigma, n_powers))
    return CoefficientCovariance(free, n_powers, noise, pointing, excess, variance,
                                 model_temperatures_c=np.asarray(setpoint_temperatures_c, dtype=float),
                                 model_variance_by_temperature=local)


def model_variance(residuals: np.ndarray, sigma: np.ndarray, free: np.ndarray, n_fitted: int,
                   residual_sigma: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per parameter, the variance of the per-setpoint estimates about the polynomial beyond their 1σ, when
    their χ² is significant at the 95 % level (K − `n_fitted` degrees of freedom); zero otherwise, and when
    there is nothing left to check: (12,) over the whole range, and (K, 12) at each setpoint.

    At a setpoint it is that setpoint's own residual squared less what its noise alone leaves in it
    (`residual_sigma`², the residual's variance: σ²(1 − leverage), the polynomial having been fitted
    through it), not below zero: the misfit where it is, not spread over the range (a polynomial that
    cannot follow one end misses there, not everywhere)."""
    variance, local = np.zeros(12), np.zeros((len(residuals), 12))
    dof = len(residuals) - n_fitted
    if dof <= 0:
        return variance, local
    residual_sigma = sigma if residual_sigma is None else residual_sigma
    for k in np.flatnonzero(free):
        statistic = float(np.sum((residuals[:, k] / sigma[:, k]) ** 2))
        if statistic > chi2.ppf(0.95, dof):
            variance[k] = (statistic / dof - 1.0) * float(np.mean(sigma[:, k] ** 2))
            local[:, k] = np.maximum(residuals[:, k] ** 2 - residual_sigma[:, k] ** 2, 0.0)
    return variance, local


def residual_sigma(temperatures_c: np.ndarray, sigma: np.ndarray, n_powers: int) -> np.ndarray:
    """(K, 12) the 1σ that noise alone leaves in each per-setpoint estimate's residual about its weighted
    polynomial (fit_thermal's): σ·√(1 − leverage)."""
    t = np.asarray(temperatures_c, dtype=float)
    x = (t - t.mean()) / max(float(np.ptp(t)), 1e-9)                   # leverage is the same in any scale of T
    powers = np.vander(x, n_powers, increasing=True)
    out = np.array(sigma, dtype=float, copy=True)
    for k in range(sigma.shape[1]):
        if not np.all(np.isfinite(sigma[:, k]) & (sigma[:, k] > 0)):
            continue
        weights = 1.0 / sigma[:, k] ** 2
        hat = powers @ np.linalg.solve(powers.T @ (weights[:, None] * powers), powers.T * weights)
        out[:, k] = sigma[:, k] * np.sqrt(np.clip(1.0 - np.diagonal(hat), 0.0, 1.0))
    return out


def output_uncertainty(raw_g: np.ndarray, temperature_c: np.ndarray, model: ThermalModel,
                       covariance: CoefficientCovariance, reading_stderr_g: np.ndarray, temperature_u_c: np.ndarray,
                       gravity_relative_u: float, out_of_range: OutOfRange = "extrapolate",
                       size_source: str = "gravity") -> dict[str, np.ndarray]:
    """Per source, the standard uncertainty (n, 3) in g of `raw_g` (n, 3) compensated at `temperature_c` (n,);
    `size_source` names the reference size's (its relative uncertainty `gravity_relative_u`)."""
    raw_g = np.asarray(raw_g, dtype=float)
    temperature_c = np.asarray(temperature_c, dtype=float)
    params = model.parameters_at(temperature_c, out_of_range)            # (n, 12)
    output = correct(raw_g, params)
    by_parameter = correct_jacobian(raw_g, params)                    # (n, 3, 12)
    by_coefficient = _by_coefficient(by_parameter, temperature_c, model, covariance, out_of_range)
    rows = by_coefficient.reshape(3 * len(raw_g), by_coefficient.shape[-1])  # (n·3, P)

    def through(cov: np.ndarray) -> np.ndarray:
        """√(dᵀ·cov·d) per output and axis, d its derivatives by the coefficients (a product, not a sum of
        n·3·P² terms)."""
        return np.sqrt(np.maximum(np.einsum("ip,ip->i", rows @ cov, rows), 0.0)).reshape(raw_g.shape)

    gain = error_matrix(params)                                        # ∂output/∂raw
    reading = np.sqrt(np.einsum("nab,nb,nab->na", gain, np.asarray(reading_stderr_g, dtype=float) ** 2, gain))
    by_temperature = _by_temperature(raw_g, temperature_c, model, out_of_range)
    model_u = np.sqrt(np.einsum("nap,np,nap->na", by_parameter, covariance.model_variance_at(temperature_c),
                                by_parameter))
    sources = {
        "reading_noise": reading,
        "calibration_noise": through(covariance.noise),
        "turntable_pointing": through(covariance.pointing),
        "scatter_beyond_noise": through(covariance.excess),
        "thermal_model": model_u,
    }
    if covariance.hysteresis is not None:  # not measured is not zero: budget.not_included says so
        sources["hysteresis"] = np.sqrt(np.einsum("nab,b,nab->na", gain, covariance.hysteresis**2, gain))
    sources["temperature"] = np.abs(by_temperature) * np.asarray(temperature_u_c, dtype=float)[:, None]
    sources[size_source] = np.abs(output) * gravity_relative_u
    return sources


def _by_coefficient(by_parameter: np.ndarray, temperature_c: np.ndarray, model: ThermalModel,
                    covariance: CoefficientCovariance, out_of_range: OutOfRange) -> np.ndarray:
    """The compensated output's derivatives (n, 3, P) by the thermal model's free coefficients."""
    x = model.scaled(temperature_c)
    if out_of_range == "clamp":
        x = np.clip(x, -1.0, 1.0)
    powers = np.vander(x, covariance.n_powers, increasing=True)       # (n, m)
    return np.einsum("nap,nm->napm", by_parameter[:, :, covariance.free], powers).reshape(len(by_parameter), 3, -1)


def _by_temperature(raw_g: np.ndarray, temperature_c: np.ndarray, model: ThermalModel,
                    out_of_range: OutOfRange) -> np.ndarray:
    """The compensated output's derivative (n, 3) by the temperature it is compensated at, per °C."""
    warmer = correct(raw_g, model.parameters_at(temperature_c + _STEP_C, out_of_range))
    cooler = correct(raw_g, model.parameters_at(temperature_c - _STEP_C, out_of_range))
    return (warmer - cooler) / (2 * _STEP_C)


def magnitude_noise_u(raw_g: np.ndarray, temperature_c: np.ndarray, model: ThermalModel,
                      covariance: CoefficientCovariance, temperature_u_c: np.ndarray,
                      out_of_range: OutOfRange) -> np.ndarray:
    """Each compensated reading's magnitude standard uncertainty (n,) from the noise of the calibration poses
    (through the coefficients, their correlations kept) and of the temperature it is compensated at: what noise
    adds to a check's Eq. 9 error beyond its own reading's. Random from calibration to calibration, unlike the
    pointing and the model's lack of fit."""
    raw_g = np.asarray(raw_g, dtype=float)
    temperature_c = np.asarray(temperature_c, dtype=float)
    params = model.parameters_at(temperature_c, out_of_range)
    output = correct(raw_g, params)
    direction = output / np.linalg.norm(output, axis=1, keepdims=True)
    by_coefficient = _by_coefficient(correct_jacobian(raw_g, params), temperature_c, model, covariance, out_of_range)
    along = np.einsum("na,nap->np", direction, by_coefficient)        # d|output| by each coefficient
    fit_var = np.maximum(np.einsum("np,pq,nq->n", along, covariance.noise, along), 0.0)
    slope = np.einsum("na,na->n", direction, _by_temperature(raw_g, temperature_c, model, out_of_range))
    return np.sqrt(fit_var + (slope * np.asarray(temperature_u_c, dtype=float)) ** 2)


def combined(sources: dict[str, np.ndarray]) -> np.ndarray:
    """The combined standard uncertainty: the sources in quadrature (taken as uncorrelated)."""
    return np.sqrt(sum(u**2 for u in sources.values()))


def consistency(errors: np.ndarray, calibration_u: np.ndarray, measurement_u: np.ndarray) -> dict[str, Any]:
    """The verification records' axis errors against their combined expanded uncertainty, the calibration's (the
    budget's, at each record) with the verification measurement's (its noise, its reference): the share with
    E_n = |error| / U ≤ 1 (ISO 13528's E_n), where about 95 % are expected of an uncertainty that covers what it
    states. What a lab can check without a truth: both parts are stated on the certificate."""
    expanded = COVERAGE_FACTOR * np.hypot(calibration_u, measurement_u)
    e_n = np.abs(errors) / np.maximum(expanded, 1e-15)
    return {"axis_errors": int(e_n.size), "within_share": float(np.mean(e_n <= 1.0)),
            "largest_e_n": float(e_n.max())}
