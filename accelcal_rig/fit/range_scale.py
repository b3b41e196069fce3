"""A gyroscope measured at more than one range (engine/step_ranges.py: at rest and at low rates at a finer one):
each other range's sensitivity relative to the channel's own range, so that one rate-table model serves both.

A part's sensitivity differs a little from range to range (the data sheet's tolerance is per range). At each
setpoint the model (fit/gyro_model.py) is fitted to every calibration record together with one relative scale
ε per axis for each other range: a record at such a range reads (1 + ε) × what the model says at the channel's
range. Its rate steps at the finer range and those at the channel's own (the procedure's rates below and above
80 % of the finer range, each about every axis) tell ε from K; the nonlinearity term needs two rates at the
channel's own range to be told from ε. ε is taken as constant over temperature: its weighted mean over the
setpoints, its 1σ widened by √χ²_red of their scatter when they scatter more than their own 1σ say. The
records at the other range are then divided by (1 + ε) and the fit goes on as for one range.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from accelcal_rig.fit import gyro_model

#: ε's scatter over the setpoints beyond this χ²_red (against each setpoint's own 1σ) widens its 1σ.
_CHI2_WIDEN_ABOVE = 1.0


@dataclass(frozen=True)
class RangeScale:
    """One other range's sensitivity relative to the channel's range, per axis: readings there are (1 + ε) ×."""

    range: float
    scale: np.ndarray             # (3,) 1 + ε
    sigma: np.ndarray             # (3,) 1σ of the scale
    setpoints: int                # how many setpoints' fits it is the mean of
    chi2_reduced: float | None    # of the setpoints' ε about their mean (None with one setpoint)


class RangeScaleError(ValueError):
    """The records at another range cannot be tied to the channel's range (no rate steps there, or no setpoint
    with rate steps at both)."""


def fit_range_scales(mean_dps: np.ndarray, stderr_dps: np.ndarray, reference_dps: np.ndarray, force_g: np.ndarray,
                     range_dps: np.ndarray, setpoint_c: np.ndarray, own_range: float,
                     stderr_floor_dps: float) -> list[RangeScale]:
    """Each range other than `own_range` among the calibration records' `range_dps`, fitted at every setpoint
    whose records turn at both ranges and combined over them."""
    others = sorted({float(r) for r in range_dps} - {float(own_range)})
    if not others:
        return []
    per_range: dict[float, list[tuple[np.ndarray, np.ndarray]]] = {r: [] for r in others}
    failed: list[str] = []
    for setpoint in dict.fromkeys(setpoint_c.tolist()):
        rows = setpoint_c == setpoint
        turning = np.linalg.norm(reference_dps, axis=1) > 1.0
        present = [r for r in others if np.any(rows & turning & (range_dps == r))]
        if not present or not np.any(rows & turning & (range_dps == own_range)):
            continue
        try:
            estimates = _fit_setpoint(mean_dps[rows], stderr_dps[rows], reference_dps[rows], force_g[rows],
                                      range_dps[rows], present, stderr_floor_dps)
        except (np.linalg.LinAlgError, ValueError) as exc:
            failed.append(f"{setpoint:g} °C: {exc}")
            continue
        for r, estimate in estimates.items():
            per_range[r].append(estimate)
    scales = []
    for r in others:
        if not per_range[r]:
            why = f" (fits that failed: {'; '.join(failed)})" if failed else ""
            raise RangeScaleError(f"records at ±{r:g} °/s but no setpoint whose rate steps turn at both it and the "
                                  f"channel's ±{own_range:g} °/s and determine the model: its sensitivity cannot be "
                                  f"tied to the channel's{why}")
        values = np.array([v for v, _ in per_range[r]])
        sigmas = np.array([s for _, s in per_range[r]])
        weights = 1.0 / sigmas**2
        mean = (values * weights).sum(axis=0) / weights.sum(axis=0)
        sigma = 1.0 / np.sqrt(weights.sum(axis=0))
        chi2 = None
        if len(values) > 1:
            chi2 = float((((values - mean) / sigmas) ** 2).sum() / (3 * (len(values) - 1)))
            if chi2 > _CHI2_WIDEN_ABOVE:
                sigma = sigma * np.sqrt(chi2)  # ε moves with temperature more than its noise: say so in its 1σ
        scales.append(RangeScale(r, 1.0 + mean, sigma, len(values), chi2))
    return scales


def _fit_setpoint(mean_dps: np.ndarray, stderr_dps: np.ndarray, reference_dps: np.ndarray, force_g: np.ndarray,
                  range_dps: np.ndarray, others: list[float],
                  stderr_floor_dps: float) -> dict[float, tuple[np.ndarray, np.ndarray]]:
    """ε and its 1σ for each of `others` at one setpoint, with the model's 27 parameters beside them."""
    sigma = np.maximum(np.asarray(stderr_dps, dtype=float), stderr_floor_dps)
    n_model = gyro_model.N_PARAMETERS
    at = [range_dps == r for r in others]
    if 3 * len(mean_dps) <= n_model + 3 * len(others):
        raise ValueError(f"{len(mean_dps)} records for {n_model + 3 * len(others)} parameters")

    def factors(epsilon: np.ndarray) -> np.ndarray:
        scale = np.ones_like(mean_dps)
        for k, rows in enumerate(at):
            scale[rows] = 1.0 + epsilon[3 * k:3 * k + 3]
        return scale

    def residuals(p: np.ndarray) -> np.ndarray:
        model = gyro_model.distort_rate(reference_dps, force_g, p[:n_model])
        return ((factors(p[n_model:]) * model - mean_dps) / sigma).ravel()

    def jacobian(p: np.ndarray) -> np.ndarray:
        scale = factors(p[n_model:])
        model_jacobian = gyro_model.distort_jacobian(reference_dps, force_g, p[:n_model]) * scale[:, :, None]
        model = gyro_model.distort_rate(reference_dps, force_g, p[:n_model])
        extra = np.zeros(mean_dps.shape + (3 * len(others),))
        for k, rows in enumerate(at):
            for axis in range(3):
                extra[rows, axis, 3 * k + axis] = model[rows, axis]
        full = np.concatenate([model_jacobian, extra], axis=2) / sigma[:, :, None]
        return full.reshape(-1, n_model + 3 * len(others))

    start = np.concatenate([gyro_model.IDENTITY_PARAMETERS, np.zeros(3 * len(others))])
    result = least_squares(residuals, start, jac=jacobian, method="lm", xtol=1e-12, ftol=1e-12)
    dof = result.fun.size - result.x.size
    covariance = np.linalg.inv(result.jac.T @ result.jac) * max(float(result.fun @ result.fun) / dof, 1.0)
    spread = np.sqrt(np.diag(covariance))
    return {r: (result.x[n_model + 3 * k:n_model + 3 * k + 3], spread[n_model + 3 * k:n_model + 3 * k + 3])
            for k, r in enumerate(others)}


def to_own_range(mean_dps: np.ndarray, stderr_dps: np.ndarray, range_dps: np.ndarray,
                 scales: list[RangeScale]) -> tuple[np.ndarray, np.ndarray]:
    """Readings (and their standard errors) at other ranges as the channel's range would read them."""
    mean, stderr = np.array(mean_dps, dtype=float), np.array(stderr_dps, dtype=float)
    for scale in scales:
        rows = range_dps == scale.range
        mean[rows] /= scale.scale
        stderr[rows] /= scale.scale
    return mean, stderr
